"""The served plant: software in the loop against the in-process slew, and bad clients.

The SIL test runs two processes on loopback: the plant (this process,
:func:`flexsat.realtime.server.serve`, faster than real time with ``speed``) and the
reference flight software (``flexsat fsw``, another interpreter). The protocol
answers sensor packet k with the command applied at instant k + 1: a transport
delay of exactly one control period, the ``delay`` stage with ``periods = 1``
(docs/realtime.md, 'Timing'). No assertion here depends on timing: the SIL test is
run lock-step (a late command is waited for, not held), and the paced run's test
checks only the bookkeeping.
"""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

from flexsat.analysis.requirements import slew_metrics
from flexsat.config import nominal
from flexsat.dynamics.plant import Plant
from flexsat.errors import ConfigError
from flexsat.realtime import packets
from flexsat.realtime.client import PlantClient
from flexsat.realtime.server import fifo_priority, serve
from flexsat.realtime.transport import client_link, plant_link
from flexsat.simulate import SlewScenario, load_slew, run_slew
from tests.cli.harness import flexsat

# A short PD slew: 5 deg in roll, the law at 100 Hz, RK4 at 1 ms. R1's band is opened
# to 3 deg so that the six-second run has verdicts of both kinds: R1 and R3 pass, R2
# (1e-3 deg/s, the thesis's) fails, the satellite still turning.
SCENARIO = """
name = "sil"
duration_s = 6.0
dt_s = 0.001
control_dt_s = 0.01
record_dt_s = 0.01
target_euler_deg = [5.0, 0.0, 0.0]
[controller]
kind = "pd"
[requirements]
pointing_deg = 3.0
settling_deadline_s = 5.0
"""


def free_ports(count: int) -> list[int]:
    """Loopback UDP ports free now (bound to port 0, then released)."""
    sockets = [socket.socket(socket.AF_INET, socket.SOCK_DGRAM) for _ in range(count)]
    for s in sockets:
        s.bind(("127.0.0.1", 0))
    ports = [s.getsockname()[1] for s in sockets]
    for s in sockets:
        s.close()
    return ports


@pytest.fixture
def endpoints():
    sensor, command = free_ports(2)
    return f"udp://127.0.0.1:{sensor}", f"udp://127.0.0.1:{command}"


@pytest.fixture
def scenario_file(tmp_path):
    path = tmp_path / "sil.toml"
    path.write_text(SCENARIO)
    return path


def _fsw(scenario_file, sensor: str, command: str) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "flexsat", "fsw", str(scenario_file), "--sensor-endpoint", sensor,
         "--command-endpoint", command, "--json", "--connect-timeout", "300"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip


def test_the_sil_slew_reproduces_the_in_process_slew_with_one_period_of_delay(
    scenario_file, endpoints
):
    plant = Plant.from_config(nominal())
    scenario = load_slew(scenario_file)
    link = plant_link(*endpoints)
    client = _fsw(scenario_file, *endpoints)
    try:
        served, stats = serve(plant, scenario, link, speed=5.0, lockstep=True,
                              client_timeout_s=30.0, start_timeout_s=300.0)  # fmt: skip
    finally:
        link.close()
        out, err = client.communicate(timeout=120)
    assert client.returncode == 0, err
    assert '"ended": "end"' in out
    assert served.ok and stats.stopped == ""
    assert stats.instants == 601 and stats.commands == 600  # the last sample is not answered
    assert stats.overruns == 0 and stats.malformed == 0

    delayed = scenario.model_dump()
    delayed["actuator_stages"] = [{"kind": "delay", "periods": 1}]
    reference = run_slew(plant, SlewScenario.model_validate(delayed))
    a = served.dataset["pointing_error_deg"].values
    b = reference.dataset["pointing_error_deg"].values
    # The same law step on the same float64 inputs (carried bit for bit in the packets),
    # the same RK4 chunks and stages: the histories agree to round-off. 1e-12 deg leaves
    # room for a compiler reordering a sum, nothing for a missing or extra period (see
    # the control below, 1e-3 deg apart).
    np.testing.assert_allclose(a, b, rtol=0.0, atol=1e-12)
    tau, tau_ref = (r.dataset["tau_applied"].values for r in (served, reference))
    np.testing.assert_allclose(tau, tau_ref, rtol=0.0, atol=1e-12)
    mine, theirs = slew_metrics(served.dataset), slew_metrics(reference.dataset)
    for verdict in ("r1_pass", "r2_pass", "r3_pass"):
        assert mine[verdict] == theirs[verdict], verdict
    assert (theirs["r1_pass"], theirs["r2_pass"], theirs["r3_pass"]) == (True, False, True)

    # control: without the delay stage the in-process slew is another history
    undelayed = run_slew(plant, scenario).dataset["pointing_error_deg"].values
    assert np.abs(undelayed - a).max() > 1e-3


def _raw_sender(endpoint: str):
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    host, port = endpoint.removeprefix("udp://").split(":")
    return sock, (host, int(port))


def test_malformed_packets_are_counted_and_a_silent_client_ends_the_run(endpoints):
    scenario = SlewScenario.model_validate(
        {"duration_s": 2.0, "control_dt_s": 0.01, "record_dt_s": 0.01,
         "controller": {"kind": "pd"}}
    )  # fmt: skip
    plant = Plant.from_config(nominal())
    torques = [np.array([0.1, -0.2, 0.05]) * (i + 1) / 10 for i in range(10)]
    lines: list[str] = []
    bad = [b"junk", packets.encode_hello()[:-1],
           bytes(4) + packets.encode_command(0, 0, 0, 0, np.zeros(3))[4:]]  # fmt: skip

    def client():
        raw, to = _raw_sender(endpoints[1])
        link = client_link(*endpoints)
        try:
            raw.sendto(bad[0], to)  # before HELLO: counted too
            plant_client = PlantClient(link)
            sensor = plant_client.connect(300.0)
            for torque in torques:  # answer ten samples, a bad packet before each
                raw.sendto(bad[1 + len(lines) % 2], to)
                plant_client.command(sensor, torque)
                sensor = plant_client.next(30.0)
            # then vanish: no more commands
        finally:
            link.close()
            raw.close()

    link = plant_link(*endpoints)
    thread = threading.Thread(target=client)
    thread.start()
    try:
        result, stats = serve(plant, scenario, link, speed=10.0, lockstep=True,
                              client_timeout_s=0.5, start_timeout_s=300.0,
                              log=lines.append)  # fmt: skip
    finally:
        link.close()
        thread.join(timeout=60)
    assert stats.malformed == 11 and len(lines) == 11
    assert all(line.startswith("dropped a malformed packet: ") for line in lines)
    assert any("magic 0x00000000" in line for line in lines)
    assert stats.commands == 10 and stats.late == 0
    # commands 0-9 applied at instants 1-10; at instant 11 the client is silent: the run
    # stops there, its records end at the last record before it (t = 0.10 s)
    assert "client silent for 0.5 s" in stats.stopped and "t = 0.11 s" in stats.stopped
    ds = result.dataset
    assert ds["time"].values[-1] == pytest.approx(0.10, abs=1e-12)
    # the last record holds the last command (the actuator's gain 0.95 applies later)
    np.testing.assert_array_equal(ds["tau_cmd"].values[-1], torques[-1])
    np.testing.assert_array_equal(ds["tau_cmd"].values[1], torques[0])
    assert result.dataset.attrs["realtime_stopped"] == stats.stopped


def test_a_port_in_use_is_one_message_and_exit_code_2(tmp_path, capsys, endpoints):
    (tmp_path / "s.toml").write_text('name = "served"\n')
    holder = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    host, port = endpoints[1].removeprefix("udp://").split(":")
    holder.bind((host, int(port)))
    try:
        outcome = flexsat(["serve", str(tmp_path / "s.toml"), "--sensor-endpoint", endpoints[0],
                           "--command-endpoint", endpoints[1]], capsys)  # fmt: skip
    finally:
        holder.close()
    assert outcome.code == 2
    assert f"--command-endpoint: {endpoints[1]} is in use; give another port" in outcome.stderr
    assert "Traceback" not in outcome.stderr


def test_paced_serve_and_fsw_commands_write_a_slew_s_records(tmp_path, scenario_file, endpoints):
    sensor, command = endpoints
    client = _fsw(scenario_file, sensor, command)
    start = time.perf_counter()
    served = subprocess.run(
        [sys.executable, "-m", "flexsat", "serve", str(scenario_file), "--speed", "4",
         "--sensor-endpoint", sensor, "--command-endpoint", command, "--start-timeout", "300",
         "--json", "--out", str(tmp_path / "run")],
        capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    out, err = client.communicate(timeout=120)
    print(f"serve + fsw: {time.perf_counter() - start:.1f} s wall")
    assert served.returncode == 0, served.stderr
    assert client.returncode == 0, err
    metrics = json.loads(served.stdout)
    rt = metrics["realtime"]
    # bookkeeping only (how many commands are late depends on the machine's load):
    # every instant is paced once, each command is applied, late or refused
    assert rt["instants"] == 601 and rt["stopped"] == ""
    assert rt["deadline_overruns"] <= 600 and rt["late_commands"] <= rt["commands"] <= 600
    assert rt["deadline_overruns"] >= rt["late_commands"]
    assert rt["pacing_jitter_p99_us"] >= rt["pacing_jitter_p50_us"]
    assert {"r1_pass", "r2_pass", "r3_pass"} <= metrics.keys()
    assert (tmp_path / "run" / "result.nc").is_file()
    assert (tmp_path / "run" / "metrics.json").is_file()


def test_fifo_priority_runs_the_block_under_sched_fifo_and_restores_the_policy():
    if not hasattr(os, "sched_setscheduler"):
        with pytest.raises(ConfigError, match="--priority: SCHED_FIFO is not available"):
            with fifo_priority(10):
                pass
        return
    before = os.sched_getscheduler(0)
    try:
        with fifo_priority(10):
            inside = os.sched_getscheduler(0), os.sched_getparam(0).sched_priority
    except ConfigError as error:  # not permitted here: one message, the policy unchanged
        assert "--priority: SCHED_FIFO needs the CAP_SYS_NICE capability" in str(error)
    else:
        assert inside == (os.SCHED_FIFO, 10)
    assert os.sched_getscheduler(0) == before
    with fifo_priority(None):  # the normal scheduler, left alone
        assert os.sched_getscheduler(0) == before
    with pytest.raises(ConfigError, match=r"--priority: must be in 1..99 \(SCHED_FIFO\), got 0"):
        with fifo_priority(0):
            pass

"""The real-time links: packets through UDP and ZeroMQ both ways, a served run over ZeroMQ,
endpoints in use refused."""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest

from flexsat.config import nominal
from flexsat.dynamics.plant import Plant
from flexsat.errors import ConfigError
from flexsat.realtime import packets
from flexsat.realtime.client import PlantClient
from flexsat.realtime.server import serve
from flexsat.realtime.transport import client_link, plant_link
from flexsat.simulate import SlewScenario
from tests.realtime.test_server import free_ports

pytest.importorskip("zmq")


def _first(link, timeout_s: float = 30.0, resend=None) -> bytes:
    """The next packet on ``link``, calling ``resend`` every 0.1 s until one comes."""
    end = time.perf_counter() + timeout_s
    while time.perf_counter() < end:
        if resend is not None:
            resend()
        data = link.receive(0.1)
        if data is not None:
            return data
    raise AssertionError("no packet within the timeout")


@pytest.mark.parametrize("scheme", ["udp", "tcp"])
def test_a_sensor_packet_and_its_command_cross_the_link_bit_for_bit(scheme):
    sensor, command = (f"{scheme}://127.0.0.1:{port}" for port in free_ports(2))
    plant = plant_link(sensor, command)
    client = client_link(sensor, command)
    q = np.array([0.9, 0.1, -0.3, 1.0 / 3.0])
    omega = np.array([1e-300, -2.5e-3, np.pi])
    torque = np.array([0.1, -0.2, 7.0 / 3.0])
    try:
        sent = packets.encode_sensor(7, 70_000_000, 123_456_789, q, omega)
        # Sending never blocks: over ZeroMQ a packet sent before the client's connection
        # is up has no peer and is dropped (docs/realtime.md, 'Transports and
        # endpoints'), so the plant repeats it, as the client repeats HELLO
        received = _first(client, resend=lambda: plant.send(sent))
        assert received == sent
        sample = packets.decode(received)
        np.testing.assert_array_equal(sample.q, q)  # float64 carried exactly
        np.testing.assert_array_equal(sample.omega, omega)
        client.send(packets.encode_command(7, 70_000_000, 123_456_789, 50, torque))
        answer = packets.decode(_first(plant))
        assert (answer.sequence, answer.echo_stamp_ns, answer.compute_ns) == (7, 123_456_789, 50)
        np.testing.assert_array_equal(answer.torque, torque)
    finally:
        client.close()
        plant.close()


def test_a_zeromq_endpoint_in_use_is_one_message_naming_the_option():
    sensor, command = (f"tcp://127.0.0.1:{port}" for port in free_ports(2))
    first = plant_link(sensor, command)
    try:
        with pytest.raises(ConfigError, match=r"^--sensor-endpoint: tcp://127\.0\.0\.1:\d+ .*"
                                              r"give another endpoint$"):  # fmt: skip
            plant_link(sensor, f"tcp://127.0.0.1:{free_ports(1)[0]}")
    finally:
        first.close()


def test_a_served_run_over_zeromq_applies_each_answer_one_period_later():
    """The whole protocol over tcp://: the client's first packet may be dropped before
    its connection is up; the plant repeats it on the next HELLO (lock-step run)."""
    sensor, command = (f"tcp://127.0.0.1:{port}" for port in free_ports(2))
    scenario = SlewScenario.model_validate(
        {"duration_s": 0.3, "control_dt_s": 0.01, "record_dt_s": 0.01,
         "controller": {"kind": "pd"}}
    )  # fmt: skip
    plant = Plant.from_config(nominal())

    def client():
        link = client_link(sensor, command)
        try:
            remote = PlantClient(link)
            packet = remote.connect(300.0)
            while isinstance(packet, packets.Sensor):
                remote.command(packet, np.array([1e-3 * packet.sequence, 0.0, 0.0]))
                packet = remote.next(30.0)
        finally:
            link.close()

    link = plant_link(sensor, command)
    thread = threading.Thread(target=client)
    thread.start()
    try:
        result, stats = serve(plant, scenario, link, speed=10.0, lockstep=True,
                              client_timeout_s=30.0, start_timeout_s=300.0)  # fmt: skip
    finally:
        link.close()
        thread.join(timeout=60)
    assert stats.stopped == "" and stats.instants == 31 and stats.commands == 30
    assert stats.overruns == 0 and stats.late == 0 and stats.malformed == 0
    # the answer to sample k (torque 1e-3 k about x) is the command from instant k + 1
    tau = result.dataset["tau_cmd"].values
    np.testing.assert_array_equal(tau[1:, 0], 1e-3 * np.arange(30))
    np.testing.assert_array_equal(tau[0], np.zeros(3))

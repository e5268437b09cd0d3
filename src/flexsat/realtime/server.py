"""The plant paced to the wall clock: sensor packets out, torque commands in.

The slew's plant, sensing and actuation chains run as in
:func:`flexsat.simulate.run_slew` with a Python controller
(:mod:`flexsat.simulate.python_loop`): the compiled RK4 at the scenario's ``dt_s``
in chunks of a control period, the compiled stages at each control instant. In
place of the law, at instant k the plant waits for the wall clock to reach
t_k / speed (a short sleep that wakes on arriving packets, then a spin on
``time.perf_counter``), applies the command answering the sensor packet k - 1 if it
has arrived (else holds the previous one: a deadline overrun), then sends the
sensor chain's output of instant k. The protocol's transport delay is so one
control period, the ``delay`` stage with ``periods = 1`` (``docs/realtime.md``,
'Timing').
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np

from flexsat.control.stages import JOINT_ACTUATORS, REFERENCES
from flexsat.dynamics.plant import Plant
from flexsat.errors import ConfigError, SimulationError
from flexsat.realtime import packets
from flexsat.realtime.transport import Link, check_seconds
from flexsat.simulate.closedloop import finish_slew, prepare_slew
from flexsat.simulate.python_loop import python_loop
from flexsat.simulate.result import Result
from flexsat.simulate.scenario import SlewScenario

__all__ = ["MAX_SPEED", "SPIN_S", "ServeStats", "check_options", "check_priority",
           "fifo_priority", "serve"]  # fmt: skip

SPIN_S = 1e-3
"""The pacing spins on the clock for the last this long before an instant [s]; before
that it sleeps in the link's wait, woken by any packet."""
MAX_SPEED = 1000.0
"""Fastest pacing allowed: simulated seconds per wall second [-]."""
_MAX_LOG_LINES = 20  # malformed packets logged one line each, up to this many


@dataclass
class ServeStats:
    """What a served run measured.

    Attributes
    ----------
    instants : int
        Control instants paced [-].
    commands : int
        Valid commands received [-].
    overruns : int
        Instants whose command (the answer to the previous sensor packet) had not
        arrived: the previous command was held [-].
    late : int
        Commands that arrived after their deadline, dropped [-].
    malformed : int
        Packets dropped for a wrong magic, version, type or length [-].
    lateness_s : list of float
        Per instant, wall clock minus the paced time t / speed when the instant ran [s].
    latency_s : list of float
        Per command, its arrival minus its sensor packet's sending, both on the plant's
        clock (the client returns the stamp) [s].
    compute_s : list of float
        Per command, the client's reported time from receipt to sending [s].
    stopped : str
        Why the run ended before its duration ("" when it did not).
    """

    instants: int = 0
    commands: int = 0
    overruns: int = 0
    late: int = 0
    malformed: int = 0
    lateness_s: list[float] = field(default_factory=list)
    latency_s: list[float] = field(default_factory=list)
    compute_s: list[float] = field(default_factory=list)
    stopped: str = ""

    def summary(self) -> dict:
        """The counts and the 50th, 99th and largest of each timing, in us (JSON-ready)."""
        out: dict = {"instants": self.instants, "commands": self.commands,
                     "deadline_overruns": self.overruns, "late_commands": self.late,
                     "malformed_packets": self.malformed, "stopped": self.stopped}  # fmt: skip
        for name, values in (("pacing_jitter", self.lateness_s), ("latency", self.latency_s),
                             ("client_compute", self.compute_s)):  # fmt: skip
            data = np.asarray(values, dtype=float) * 1e6
            for label, value in (("p50", 50), ("p99", 99), ("max", 100)):
                out[f"{name}_{label}_us"] = float(np.percentile(data, value)) if data.size else None
        return out


class _Stop(Exception):
    """The client is gone: end the run at the current instant."""


class _RemoteLaw:
    """The python loop's controller: paces, exchanges packets, returns the held command."""

    def __init__(self, link: Link, scenario: SlewScenario, speed: float, lockstep: bool,
                 client_timeout_s: float, log: Callable[[str], None]) -> None:  # fmt: skip
        self.link, self.speed, self.lockstep = link, speed, lockstep
        self.control_dt = scenario.control_dt_s
        self.timeout = client_timeout_s
        self.log = log
        self.stats = ServeStats()
        self.held = np.zeros(3)  # zero before the first command arrives
        self.answer: np.ndarray | None = None  # the command answering the last packet
        self.k = 0
        self.last_sent: bytes | None = None  # the last sensor packet sent
        self.start = 0.0
        self.last_heard = 0.0

    def wait_for_client(self, timeout_s: float) -> None:
        """Block until a HELLO arrives (the client is ready), at most ``timeout_s`` [s]."""
        end = time.perf_counter() + timeout_s
        while (left := end - time.perf_counter()) > 0.0:
            data = self.link.receive(min(left, 0.1))
            if data is None:
                continue
            try:
                packet = packets.decode(data)
            except packets.PacketError as error:
                self._malformed(error)
                continue
            if isinstance(packet, packets.Header) and packet.type == packets.HELLO:
                self.start = self.last_heard = time.perf_counter()
                return
        raise SimulationError(f"no client said HELLO within {timeout_s:g} s (--start-timeout)")

    def _malformed(self, error: Exception) -> None:
        self.stats.malformed += 1
        if self.stats.malformed <= _MAX_LOG_LINES:
            self.log(f"dropped a malformed packet: {error}")
        elif self.stats.malformed == _MAX_LOG_LINES + 1:
            self.log("more malformed packets: counted, no longer logged")

    def _take(self, data: bytes) -> None:
        """Handle one received packet at instant ``self.k`` (before its sensor packet)."""
        now = time.perf_counter()
        try:
            packet = packets.decode(data)
        except packets.PacketError as error:
            self._malformed(error)
            return
        if not isinstance(packet, packets.Command):
            # a repeated HELLO: before its first command, the client has not had a
            # sensor packet (over ZeroMQ one sent before its connection was up is
            # dropped): send it the last one again
            if packet.type == packets.HELLO and self.stats.commands == 0 and self.last_sent:
                self.last_heard = now
                self.link.send(self.last_sent)
            return
        self.last_heard = now
        self.stats.commands += 1
        self.stats.latency_s.append((time.monotonic_ns() - packet.echo_stamp_ns) * 1e-9)
        self.stats.compute_s.append(packet.compute_ns * 1e-9)
        if packet.sequence == self.k - 1 and np.all(np.isfinite(packet.torque)):
            self.answer = packet.torque
        else:
            self.stats.late += 1

    def _pace(self, target: float) -> None:
        """Receive packets until the wall clock reaches ``target`` [s, perf_counter]."""
        while (left := target - time.perf_counter()) > 0.0:
            data = self.link.receive(left - SPIN_S if left > 2.0 * SPIN_S else 0.0)
            if data is not None:
                self._take(data)
        while (data := self.link.receive(0.0)) is not None:
            self._take(data)

    def __call__(self, t: float, q: np.ndarray, omega: np.ndarray) -> np.ndarray:
        self.k = k = round(t / self.control_dt)
        target = self.start + t / self.speed
        self._pace(target)
        self.stats.lateness_s.append(time.perf_counter() - target)
        if k > 0 and self.answer is None and self.lockstep:
            end = time.perf_counter() + self.timeout
            while self.answer is None and (left := end - time.perf_counter()) > 0.0:
                data = self.link.receive(left)
                if data is not None:
                    self._take(data)
        if k > 0:
            if self.answer is None:
                self.stats.overruns += 1
                if time.perf_counter() - self.last_heard > self.timeout:
                    self.stats.stopped = (f"client silent for {self.timeout:g} s (--client-"
                                          f"timeout): stopped at t = {t:.6g} s")  # fmt: skip
                    raise _Stop
            else:
                self.held = self.answer
        self.answer = None
        self.stats.instants += 1
        self.last_sent = packets.encode_sensor(k, round(t * 1e9), time.monotonic_ns(), q, omega)
        self.link.send(self.last_sent)
        return self.held


def check_options(speed: float, client_timeout_s: float, start_timeout_s: float) -> None:
    """Refuse a speed outside (0, :data:`MAX_SPEED`] or a timeout outside (0, 3600] s.

    Parameters
    ----------
    speed : float
        Simulated seconds per wall second [-].
    client_timeout_s, start_timeout_s : float
        The timeouts of :func:`serve` [s].

    Raises
    ------
    ConfigError
        Naming the option (``--speed``, ``--client-timeout``, ``--start-timeout``).
    """
    if not 0.0 < speed <= MAX_SPEED:
        raise ConfigError(f"--speed: must be in (0, {MAX_SPEED:g}], got {speed:g}")
    check_seconds("--client-timeout", client_timeout_s)
    check_seconds("--start-timeout", start_timeout_s)


def check_priority(priority: int | None) -> None:
    """Refuse a SCHED_FIFO priority outside 1-99 (None: the normal scheduler).

    Parameters
    ----------
    priority : int or None
        Real-time priority [-].

    Raises
    ------
    ConfigError
        Naming ``--priority``.
    """
    if priority is not None and not 1 <= priority <= 99:
        raise ConfigError(f"--priority: must be in 1..99 (SCHED_FIFO), got {priority}")


@contextmanager
def fifo_priority(priority: int | None) -> Iterator[None]:
    """Run the block under Linux's SCHED_FIFO at ``priority``, then restore the policy.

    A process of this policy runs as soon as it is runnable, ahead of every normal
    process: the pacing's sleep wakes on time on a loaded machine. It never spins
    for long (the pacing spins the last :data:`SPIN_S` before each instant, the rest
    is sleeping), so the other processes keep the processor between instants.

    Parameters
    ----------
    priority : int or None
        1 (lowest) to 99 [-]; None: leave the scheduler alone.

    Raises
    ------
    ConfigError
        A priority outside 1-99, a system without SCHED_FIFO, or no permission
        (CAP_SYS_NICE, or root).
    """
    check_priority(priority)
    if priority is None:
        yield
        return
    if not hasattr(os, "sched_setscheduler"):
        raise ConfigError("--priority: SCHED_FIFO is not available on this system (Linux only)")
    policy, param = os.sched_getscheduler(0), os.sched_getparam(0)
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
    except PermissionError:
        raise ConfigError("--priority: SCHED_FIFO needs the CAP_SYS_NICE capability (or root); "
                          "run without --priority") from None  # fmt: skip
    try:
        yield
    finally:
        os.sched_setscheduler(0, policy, param)


def _compile(plant: Plant, scenario: SlewScenario) -> None:
    """Fly one control period of ``scenario`` under zero torque: the python loop's
    compiled pieces are compiled (or loaded from the disk cache) before the paced run."""
    short = scenario.model_copy(update={"duration_s": scenario.control_dt_s})
    run = prepare_slew(plant, short)
    python_loop(plant, short, run.x, run.frame, run.stages, run.data, run.rec_t, run.rec_x,
                run.rec_ctrl, run.rec_frame, None, None, lambda t, q, w: np.zeros(3),
                run.layout.continuous)  # fmt: skip


def serve(plant: Plant, scenario: SlewScenario, link: Link, *, speed: float = 1.0,
          lockstep: bool = False, client_timeout_s: float = 1.0, start_timeout_s: float = 60.0,
          log: Callable[[str], None] | None = None,
          priority: int | None = None) -> tuple[Result, ServeStats]:  # fmt: skip
    """Fly ``scenario`` with the law outside: a client over ``link`` sends the torques.

    Parameters
    ----------
    plant : Plant
        The truth plant.
    scenario : SlewScenario
        The slew: its plant step, control and record periods, sensing and actuation
        chains; its ``controller`` is not run (the client's law replaces it).
    link : Link
        The plant's side of the link (:func:`flexsat.realtime.transport.plant_link`).
    speed : float
        Simulated seconds per wall second, in (0, :data:`MAX_SPEED`] [-].
    lockstep : bool
        Wait for each command instead of holding a late one (a deterministic loop,
        paced no faster than ``speed``); a wait longer than ``client_timeout_s`` ends
        the run.
    client_timeout_s : float
        A client silent this long [s, wall] is gone: the run stops there (the
        records up to the instant, ``ServeStats.stopped`` says why).
    start_timeout_s : float
        How long to wait for the client's HELLO [s, wall].
    log : callable, optional
        Takes one line per event (malformed packets); default: stderr.
    priority : int, optional
        Run the paced loop under SCHED_FIFO at this priority, 1-99
        (:func:`fifo_priority`); default: the normal scheduler.

    Returns
    -------
    result : Result
        As :func:`flexsat.simulate.run_slew` (``controller = "remote"``); the law's
        diagnostics are NaN.
    stats : ServeStats
        Overruns, dropped packets, pacing jitter and latency.

    Raises
    ------
    ConfigError
        A speed, timeout or priority out of range, SCHED_FIFO refused, or a scenario
        with a reference or joint actuator (the remote law flies the step reference
        alone).
    SimulationError
        No client said HELLO within ``start_timeout_s``.
    """
    check_options(speed, client_timeout_s, start_timeout_s)
    check_priority(priority)
    run = prepare_slew(plant, scenario)
    layout = run.layout
    if (layout.reference.name != REFERENCES.default
            or layout.joint_actuator.name != JOINT_ACTUATORS.default):  # fmt: skip
        raise ConfigError("a served plant flies the step reference without joint actuators: "
                          "remove [reference] and [joint_actuator]")  # fmt: skip
    _compile(plant, scenario)  # before the client starts the clock
    law = _RemoteLaw(link, scenario, speed, lockstep, client_timeout_s,
                     log or (lambda line: print(line, file=sys.stderr)))  # fmt: skip
    with fifo_priority(priority):
        law.wait_for_client(start_timeout_s)
        start = time.perf_counter()
        try:
            status, done, rows = python_loop(plant, scenario, run.x, run.frame, run.stages,
                                             run.data, run.rec_t, run.rec_x, run.rec_ctrl,
                                             run.rec_frame, None, None, law,
                                             layout.continuous)  # fmt: skip
        except _Stop:
            status, done = 0, law.k * scenario.control_every
            rows = -(-done // scenario.record_every)
        wall = time.perf_counter() - start
    end = packets.encode_end(law.k, round(done * scenario.dt_s * 1e9))
    for _ in range(3):  # a datagram may be lost: the client needs one
        link.send(end)
    result = finish_slew(run, status, done, rows, wall, compiled_law=False)
    attrs = result.dataset.attrs
    attrs["controller"], attrs["controller_label"] = "remote", "remote law (flexsat serve)"
    attrs["realtime_speed"] = speed
    attrs["realtime_stopped"] = law.stats.stopped
    return result, law.stats

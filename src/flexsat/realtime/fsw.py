"""A reference flight software: a registered control law flown over the real-time link.

It reads the slew scenario the plant serves (the law, its gains, the target, the
control period, the torque limit) and the satellite config (the design inertia,
as :func:`flexsat.simulate.slew_design_inertia`), then answers every sensor packet
with the law's compiled step on the measured attitude and rate: the same
arithmetic the in-process slew runs, in another process (``flexsat fsw``).
"""

from __future__ import annotations

import numpy as np

from flexsat.control.laws import get_law
from flexsat.control.quaternion import target_quaternion
from flexsat.dynamics.plant import Plant
from flexsat.errors import SimulationError
from flexsat.realtime import packets
from flexsat.realtime.client import PlantClient
from flexsat.realtime.server import check_priority, fifo_priority
from flexsat.realtime.transport import Link, check_seconds
from flexsat.simulate.closedloop import slew_design_inertia
from flexsat.simulate.scenario import SlewScenario

__all__ = ["fly_remote"]


def fly_remote(plant: Plant, scenario: SlewScenario, link: Link, *,
               connect_timeout_s: float = 60.0, silence_s: float = 5.0,
               priority: int | None = None) -> dict:  # fmt: skip
    """Answer the plant's sensor packets with ``scenario.controller``'s law until END.

    Parameters
    ----------
    plant : Plant
        The satellite the design inertia is taken from (its rigidized J_tot, or the
        scenario's ``design_inertia_kg_m2``).
    scenario : SlewScenario
        The law and its gains, the step reference's target, the control period.
    link : Link
        The client's side (:func:`flexsat.realtime.transport.client_link`).
    connect_timeout_s : float
        Longest wait for the plant's first sensor packet [s].
    silence_s : float
        A plant silent this long [s] is gone: the client stops.
    priority : int, optional
        Answer under SCHED_FIFO at this priority, 1-99
        (:func:`flexsat.realtime.server.fifo_priority`); default: the normal scheduler.

    Returns
    -------
    dict
        ``answered`` (commands sent), ``malformed`` (packets dropped), ``ended``
        ("end": the plant's END packet; "silence": it went quiet).

    Raises
    ------
    ConfigError
        A timeout out of (0, 3600] s, a priority out of 1-99, or SCHED_FIFO refused.
    SimulationError
        No plant within ``connect_timeout_s``, or the law's step failed.
    """
    check_seconds("--connect-timeout", connect_timeout_s)
    check_seconds("--silence", silence_s)
    check_priority(priority)
    law = get_law(scenario.controller.kind)
    gains = np.ascontiguousarray(scenario.controller.gains(scenario.actuator), dtype=float)
    J = np.ascontiguousarray(slew_design_inertia(plant, scenario), dtype=float)
    q_d = np.ascontiguousarray(target_quaternion(scenario.target_euler_deg), dtype=float)
    omega_d, omega_dot_d = np.zeros(3), np.zeros(3)
    state, diag, tau = np.zeros(law.state_size), np.zeros(law.diag_size), np.zeros(3)
    dt = scenario.control_dt_s
    # compile (or load) the step before saying HELLO: the plant's clock starts then
    law.step(q_d, omega_d, omega_dot_d, q_d.copy(), omega_d.copy(), J, gains, state, 0.0, dt,
             tau, diag)  # fmt: skip
    state[:] = 0.0
    with fifo_priority(priority):
        return _answer(law, gains, J, q_d, state, diag, tau, scenario, link, connect_timeout_s,
                       silence_s)  # fmt: skip


def _answer(law, gains, J, q_d, state, diag, tau, scenario, link, connect_timeout_s, silence_s):
    """The loop of :func:`fly_remote`: HELLO, then one command per sensor packet."""
    omega_d, omega_dot_d = np.zeros(3), np.zeros(3)
    dt = scenario.control_dt_s
    every, step = scenario.control_every, scenario.dt_s  # t as the loop computes it
    client = PlantClient(link)
    packet: packets.Sensor | packets.Header | None = client.connect(connect_timeout_s)
    ended = "silence"
    while packet is not None:
        if isinstance(packet, packets.Header):  # END
            ended = "end"
            break
        status = law.step(q_d, omega_d, omega_dot_d, packet.q, packet.omega, J, gains, state,
                          packet.sequence * every * step, dt, tau, diag)  # fmt: skip
        if status != 0:
            raise SimulationError(f"the law's step failed (status {status}) at t = "
                                  f"{packet.sim_time_ns * 1e-9:.6g} s")  # fmt: skip
        client.command(packet, tau)
        packet = client.next(silence_s)
    return {"answered": client.answered, "malformed": client.malformed, "ended": ended}

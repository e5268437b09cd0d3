"""A slew's stage chains: the stages flown, their layout, compiled functions, data and states."""

from __future__ import annotations

import numpy as np

from flexsat.compiled.first_class import first_class
from flexsat.control.laws import LAW_SIGNATURE, get_law
from flexsat.control.quaternion import target_quaternion
from flexsat.control.registry import Channel
from flexsat.control.stages import ACTUATORS, JOINT_ACTUATORS, REFERENCES, SENSORS
from flexsat.control.stages.registry import (
    ACTUATOR_SIGNATURE,
    DERIVATIVE_SIGNATURE,
    JOINT_ACTUATOR_SIGNATURE,
    REFERENCE_SIGNATURE,
    SENSOR_SIGNATURE,
    no_derivative,
)
from flexsat.dynamics.plant import Plant
from flexsat.environment.loads import EnvironmentData, environment_data, idle_environment
from flexsat.errors import ConfigError
from flexsat.simulate.coupled import CHAIN_SLOTS, LoopFlow
from flexsat.simulate.layout import LoopLayout
from flexsat.simulate.loops import LoopData, LoopStages
from flexsat.simulate.scenario import SlewScenario

EPHEMERIS_STEP_S = 10.0
"""Step of the ephemeris a slew's environment is interpolated in [s]: the cubic Hermite
position is within 1 mm of the orbit in low Earth orbit at this step (docs/environment.md)."""

ENVIRONMENT_TORQUE = Channel(
    "environment_torque_B", "N m",
    "the environment's torque on the hub (every model's, and the magnetorquers'), held "
    "between evaluations, hub frame B", per_axis=True,
)  # fmt: skip
"""The environment's record: written at each evaluation of its loads."""
MAGNETORQUER_DIPOLE = Channel(
    "magnetorquer_dipole_B", "A m^2",
    "the magnetorquers' dipole, clipped and quantized, held between evaluations, hub frame B",
    per_axis=True,
)  # fmt: skip
"""Recorded when the scenario has ``[environment.magnetorquers]``."""

__all__ = [
    "ENVIRONMENT_TORQUE",
    "EPHEMERIS_STEP_S",
    "MAGNETORQUER_DIPOLE",
    "flown_chain",
    "loop_data",
    "loop_layout",
    "loop_stages",
    "slew_environment",
]


def flown_chain(scenario: SlewScenario) -> tuple[list, int]:
    """The stages the loop runs, in order, and how many of them sense.

    :meth:`SlewScenario.stage_chain` less the sensing stages whose work nothing reads:
    a stage without state or records each of whose outputs a later stage overwrites
    (``StageSpec.overwrites``) before any stage reads it (a stage that neither
    ``overwrites`` nor ``leaves`` an output reads it; the law reads both). So the
    ideal ``[sensor]`` ahead of a gyro and a star tracker, whose outputs they replace
    before the estimator reads them, is not run (about 0.1 us per control instant);
    every output is the same, bit for bit.

    Parameters
    ----------
    scenario : SlewScenario
        The slew.

    Returns
    -------
    chain : list of (str, StageConfig)
        The flown stages with their field paths: sensing, then actuation.
    n_sensors : int
        How many of them sense.
    """
    chain = scenario.stage_chain()
    n = 1 + len(scenario.sensor_stages)
    specs = [SENSORS.get(c.kind) for _, c in chain[:n]]

    def unread(i: int) -> bool:
        spec = specs[i]
        if spec.state_size or spec.records or not spec.overwrites:
            return False
        for output in spec.overwrites:
            for later in specs[i + 1 :]:
                if output in later.overwrites:
                    break  # replaced before anyone read it
                if output not in later.leaves:
                    return False  # read
            else:
                return False  # the law reads it
        return True

    sensing = [entry for i, entry in enumerate(chain[:n]) if not unread(i)]
    return sensing + chain[n:], len(sensing)


def _specs(scenario: SlewScenario) -> tuple:
    """The registered law, sensing and actuation stages, reference and joint actuator."""
    chain, n_sensors = flown_chain(scenario)
    sensors = tuple(SENSORS.get(c.kind) for _, c in chain[:n_sensors])
    actuators = tuple(ACTUATORS.get(c.kind) for _, c in chain[n_sensors:])
    return (get_law(scenario.controller.kind), sensors, actuators,
            REFERENCES.get(scenario.reference.kind),
            JOINT_ACTUATORS.get(scenario.joint_actuator.kind))  # fmt: skip


def loop_layout(plant: Plant, scenario: SlewScenario) -> LoopLayout:
    """Where a slew's states and records live: its law, its two stage chains, its
    reference generator and its joint actuator.

    Parameters
    ----------
    plant : Plant
        The plant flown (its state layout).
    scenario : SlewScenario
        The slew (its law and stages, by kind).

    Returns
    -------
    LoopLayout
        The offsets of the plant state, control state and record row.
    """
    return LoopLayout(plant.layout, *_specs(scenario), _environment_channels(scenario))


def _environment_channels(scenario: SlewScenario) -> tuple[Channel, ...]:
    """The environment's recorded channels: its torque when a model acts, and the
    magnetorquers' dipole when they dump."""
    config = getattr(scenario, "environment", None)
    if config is None or not config.active():
        return ()
    if config.magnetorquers is None:
        return (ENVIRONMENT_TORQUE,)
    return (ENVIRONMENT_TORQUE, MAGNETORQUER_DIPOLE)


def loop_stages(scenario: SlewScenario) -> LoopStages:
    """The compiled law and stages of a slew, as the loop takes them.

    Each is compiled with its role's signature on first use and cached on disk
    (:func:`flexsat.compiled.first_class.first_class`); no plant is needed. The chains are
    padded to a multiple of :data:`~flexsat.simulate.coupled.CHAIN_SLOTS` entries.

    Parameters
    ----------
    scenario : SlewScenario
        The slew (its law and stages, by kind).

    Returns
    -------
    LoopStages
        The first-class functions and the chains' lengths.
    """
    law, sensors, actuators, reference, joint_actuator = _specs(scenario)
    return LoopStages(
        _padded(tuple(first_class(s.step, SENSOR_SIGNATURE) for s in sensors)),
        (first_class(law.step, LAW_SIGNATURE),),
        _padded(tuple(first_class(s.step, ACTUATOR_SIGNATURE) for s in actuators)),
        _padded(tuple(first_class(s.derivative or no_derivative, DERIVATIVE_SIGNATURE)
                      for s in actuators)),
        (first_class(reference.step, REFERENCE_SIGNATURE),),
        (first_class(joint_actuator.step, JOINT_ACTUATOR_SIGNATURE),),
        len(sensors), len(actuators),
    )  # fmt: skip


def _padded(entries: tuple, filler=None) -> tuple:
    """``entries`` padded to a multiple of :data:`~flexsat.simulate.coupled.CHAIN_SLOTS`
    with ``filler`` (default: the first entry), so every chain of up to that many
    stages has one numba type and shares one compiled loop; the loop never reads the
    padding (it runs the chain's own stages, ``LoopStages.n_sensor``, ``n_actuator``).
    Arrays are padded with an empty array of their type."""
    if filler is None:
        filler = entries[0][:0] if isinstance(entries[0], np.ndarray) else entries[0]
    return entries + (filler,) * (-len(entries) % CHAIN_SLOTS)


def loop_data(layout: LoopLayout, scenario: SlewScenario, J: np.ndarray,
              plant: Plant) -> LoopData:  # fmt: skip
    """The arrays of one run, record-row pieces as views into ``held``.

    The stages' packed parameters (``StageConfig.packed``), their states as views into
    one control-state array, the coupled RK4 step's flow block, the law's gains, the
    reference and joint actuator's parameters and states; the chains padded as
    :func:`loop_stages` pads them.

    Parameters
    ----------
    layout : LoopLayout
        Where the states and records live (:func:`loop_layout`).
    scenario : SlewScenario
        The slew (its law, stages, reference and joint actuator).
    J : ndarray, shape (3, 3)
        Design inertia [kg m^2]; copied (a joint actuator may update the copy).
    plant : Plant
        The plant flown (the reference and joint actuator pack from it).

    Returns
    -------
    LoopData
        The loop's arrays, zero-initialized states [SI units of each entry].
    """
    held = np.zeros(layout.record_size)
    state = np.zeros(layout.state_size)
    chain = [c for _, c in flown_chain(scenario)[0]]
    n_sensors = len(layout.sensors)

    def packed(values) -> np.ndarray:
        return np.ascontiguousarray(values, dtype=float)

    # The coupled RK4 step carries each stage's integrated entries (the block ends with
    # the last stage that integrates any, StageConfig.integrated_size).
    block, last = layout.continuous_state, -1
    if layout.continuous:
        last = max(i for i, s in enumerate(layout.actuators) if s.derivative is not None)
        size = chain[n_sensors + last].integrated_size()
        if size is not None:
            block = slice(block.start, layout.actuator_states[last].start + size)
    m = block.stop - block.start
    evaluation, rate = np.zeros(m), np.zeros(m)

    def local(array: np.ndarray, pieces: tuple[slice, ...]) -> tuple:
        """Each stage's part of a flow array (empty for a stage outside the block)."""
        return tuple(array[max(p.start, block.start) - block.start :
                           min(p.stop, block.stop) - block.start]
                     if p.start < block.stop and block.start < p.stop else array[:0]
                     for p in pieces)  # fmt: skip

    flow = LoopFlow(
        state=state[block], eval=evaluation,
        eval_views=_padded(local(evaluation, layout.actuator_states), evaluation[:0]),
        dot=rate, dot_views=_padded(local(rate, layout.actuator_states), rate[:0]),
        rates=np.zeros(m), wrench=np.zeros(3), held=np.zeros(3), omega=np.zeros(3),
        n_derivative=last + 1,
    )  # fmt: skip

    return LoopData(
        J_design=J.copy(),  # a joint actuator may update it in place (sadm_drive, "measured")
        q_d=packed(target_quaternion(scenario.target_euler_deg)),  # the reference writes these
        omega_d=np.zeros(3),
        omega_dot_d=np.zeros(3),
        law_gains=packed(scenario.controller.gains(scenario.actuator)),
        law_state=state[layout.law_state],
        sensor_params=_padded(tuple(packed(c.packed(scenario)) for c in chain[:n_sensors])),
        sensor_state=_padded(tuple(state[p] for p in layout.sensor_states)),
        actuator_params=_padded(tuple(packed(c.packed(scenario)) for c in chain[n_sensors:])),
        actuator_state=_padded(tuple(state[p] for p in layout.actuator_states)),
        q_meas=np.zeros(4),
        omega_meas=np.zeros(3),
        held=held,
        tau_cmd=held[layout.tau_cmd],
        tau_applied=held[layout.tau_applied],
        law_diag=held[layout.law_diag],
        sensor_record=_padded(tuple(held[p] for p in layout.sensor_records)),
        actuator_record=_padded(tuple(held[p] for p in layout.actuator_records)),
        tau_between=np.zeros(3),
        flow=flow,
        reference_params=packed(scenario.reference.packed(scenario, plant)),
        reference_state=state[layout.reference_state],
        reference_record=held[layout.reference_record],
        joint_params=packed(scenario.joint_actuator.packed(scenario, plant)),
        joint_state=state[layout.joint_state],
        joint_record=held[layout.joint_record],
        Q=np.zeros(layout.plant.n_dof),
        env=slew_environment(scenario, plant, layout),
    )


def slew_environment(scenario: SlewScenario, plant: Plant,
                     layout: LoopLayout | None = None) -> EnvironmentData:  # fmt: skip
    """The environment a slew flies in: its ``[environment]`` models along the orbit its
    ``[orbit]`` table gives (the ephemeris built over the run), or none.

    Parameters
    ----------
    scenario : SlewScenario
        The slew (its ``environment`` and ``orbit`` tables, both optional).
    plant : Plant
        The plant flown (its geometry and mass elements).
    layout : LoopLayout, optional
        The loop's layout: where the magnetorquers read the wheels' momentum, and
        where the environment's record is written.

    Returns
    -------
    EnvironmentData
        Active when the scenario has an ``[environment]`` with a model that acts.
    """
    config = getattr(scenario, "environment", None)
    if config is None or not config.active():
        return idle_environment(plant.n_dof)
    orbit = getattr(scenario, "orbit", None)
    if orbit is None:
        raise ConfigError("environment: the environment models need the orbit: add an [orbit] "
                          "table to the scenario")  # fmt: skip
    from flexsat.orbit.ephemeris import build_ephemeris

    step = EPHEMERIS_STEP_S
    ephemeris = build_ephemeris(orbit, scenario.duration_s + step, step)
    column = None
    for channel, columns in layout.channels() if layout is not None else ():
        if channel.name == "wheel_momentum_B":
            column = columns.start
    periods = max(1, round(config.period_s / scenario.control_dt_s))
    record = layout.environment_record.start if layout is not None else None
    return environment_data(plant, config, ephemeris.table, ephemeris.epoch, column,
                            periods * scenario.control_every, record)  # fmt: skip

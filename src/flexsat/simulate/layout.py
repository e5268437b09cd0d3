"""Where every piece of a closed-loop run lives: plant state, law and stage states,
control-record columns. Every consumer (the loop, the drivers, the result) reads
the offsets here instead of re-deriving them."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

from flexsat.control.laws import LawSpec
from flexsat.control.registry import Channel
from flexsat.control.stages import StageSpec
from flexsat.control.stages.no_joint_actuator import NO_JOINT_ACTUATOR
from flexsat.control.stages.step_reference import STEP_REFERENCE
from flexsat.dynamics.layout import StateLayout

__all__ = ["LoopLayout"]

_LOOP_COLUMNS = ("tau_cmd", "tau_applied")


@dataclass(frozen=True)
class LoopLayout:
    """Offsets of a closed loop's state and records.

    Plant state ``x``: the plant's own :class:`~flexsat.dynamics.layout.StateLayout`
    (``plant``: q, q_dot, each appendage's block, work and dissipation).

    Control state (``state_size``,): the law's ``[law_state]``, the sensing chain's
    ``[sensor_state]`` (each stage's in chain order) and the actuation chain's
    ``[actuator_state]`` (likewise), then the reference's and the joint actuator's,
    zero at t = 0. The actuation block is one contiguous piece: the entries the
    stages' derivatives integrate live there.

    Control record row (``record_size``,), held between control instants:
    ``[tau_cmd]`` (3) and ``[tau_applied]`` (3) [N m], the law's diagnostics
    ``[law_diag]``, the sensing chain's and the actuation chain's records, then the
    reference's and the joint actuator's, then the environment's (its torque on the
    hub and the magnetorquers' dipole, when the run has an ``[environment]``).

    Parameters
    ----------
    plant : StateLayout
        The plant's state layout.
    law : LawSpec
        The control law.
    sensors, actuators : tuple of StageSpec
        The sensing and actuation chains in order (a single
        :class:`~flexsat.control.stages.StageSpec` is a chain of one).
    reference : StageSpec
        The reference generator.
    joint_actuator : StageSpec
        The joint actuator.
    environment : tuple of Channel
        The environment's recorded channels (none without an ``[environment]``),
        written by its loads at each evaluation and held between
        (:func:`flexsat.environment.loads.environment_loads`).
    """

    plant: StateLayout
    law: LawSpec
    sensors: tuple[StageSpec, ...]
    actuators: tuple[StageSpec, ...]
    reference: StageSpec = STEP_REFERENCE
    joint_actuator: StageSpec = NO_JOINT_ACTUATOR
    environment: tuple[Channel, ...] = ()

    @property
    def law_state(self) -> slice:
        return slice(0, self.law.state_size)

    @property
    def sensor_states(self) -> tuple[slice, ...]:
        return _pieces(self.law_state.stop, [s.state_size for s in self.sensors])

    @property
    def sensor_state(self) -> slice:
        return _span(self.law_state.stop, self.sensor_states)

    @property
    def actuator_states(self) -> tuple[slice, ...]:
        return _pieces(self.sensor_state.stop, [s.state_size for s in self.actuators])

    @property
    def actuator_state(self) -> slice:
        return _span(self.sensor_state.stop, self.actuator_states)

    @property
    def reference_state(self) -> slice:
        return _after(self.actuator_state, self.reference.state_size)

    @property
    def joint_state(self) -> slice:
        return _after(self.reference_state, self.joint_actuator.state_size)

    @property
    def state_size(self) -> int:
        return self.joint_state.stop

    @property
    def continuous(self) -> bool:
        """True if an actuation stage integrates states inside the RK4 steps."""
        return any(s.derivative is not None for s in self.actuators)

    @property
    def continuous_state(self) -> slice:
        """The piece of the actuation block the coupled RK4 step carries: from the first
        stage with a derivative to the last (empty without one)."""
        pieces = [p for p, s in zip(self.actuator_states, self.actuators, strict=True)
                  if s.derivative is not None]  # fmt: skip
        if not pieces:
            return slice(self.actuator_state.stop, self.actuator_state.stop)
        return slice(pieces[0].start, pieces[-1].stop)

    tau_cmd = slice(0, 3)
    tau_applied = slice(3, 6)

    @property
    def law_diag(self) -> slice:
        return _after(self.tau_applied, self.law.diag_size)

    @property
    def sensor_records(self) -> tuple[slice, ...]:
        return _pieces(self.law_diag.stop, [s.record_size for s in self.sensors])

    @property
    def sensor_record(self) -> slice:
        return _span(self.law_diag.stop, self.sensor_records)

    @property
    def actuator_records(self) -> tuple[slice, ...]:
        return _pieces(self.sensor_record.stop, [s.record_size for s in self.actuators])

    @property
    def actuator_record(self) -> slice:
        return _span(self.sensor_record.stop, self.actuator_records)

    @property
    def reference_record(self) -> slice:
        return _after(self.actuator_record, self.reference.record_size)

    @property
    def joint_record(self) -> slice:
        return _after(self.reference_record, self.joint_actuator.record_size)

    @property
    def environment_record(self) -> slice:
        return _after(self.joint_record, sum(c.size for c in self.environment))

    @property
    def record_size(self) -> int:
        return self.environment_record.stop

    def channels(self) -> Iterator[tuple[Channel, slice]]:
        """Each declared channel of the law and the stages with its record columns."""
        stages = self.sensors + self.actuators
        records = self.sensor_records + self.actuator_records
        blocks = [(self.law_diag, self.law.diagnostics)]
        blocks += [(r, s.records) for r, s in zip(records, stages, strict=True)]
        blocks += [(self.reference_record, self.reference.records),
                   (self.joint_record, self.joint_actuator.records),
                   (self.environment_record, self.environment)]  # fmt: skip
        for block, channels in blocks:
            start = block.start
            for channel in channels:
                yield channel, slice(start, start + channel.size)
                start += channel.size

    def __post_init__(self) -> None:
        for chain in ("sensors", "actuators"):
            value = getattr(self, chain)
            object.__setattr__(self, chain, (value,) if isinstance(value, StageSpec)
                               else tuple(value))  # fmt: skip
        names = [c.name for c, _ in self.channels()]
        clash = {n for n in names if names.count(n) > 1} | (set(names) & set(_LOOP_COLUMNS))
        if clash:
            raise ValueError(f"recorded channels named twice: {', '.join(sorted(clash))}")


def _pieces(start: int, sizes: list[int]) -> tuple[slice, ...]:
    out = []
    for size in sizes:
        out.append(slice(start, start + size))
        start += size
    return tuple(out)


def _span(start: int, pieces: tuple[slice, ...]) -> slice:
    return slice(start, pieces[-1].stop if pieces else start)


def _after(previous: slice, size: int) -> slice:
    return slice(previous.stop, previous.stop + size)

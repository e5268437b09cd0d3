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

    Control state (``state_size``,): the law's ``[law_state]``, the sensor's
    ``[sensor_state]``, the actuator's ``[actuator_state]``, then the reference's and
    the joint actuator's, zero at t = 0.

    Control record row (``record_size``,), held between control instants:
    ``[tau_cmd]`` (3) and ``[tau_applied]`` (3) [N m], the law's diagnostics
    ``[law_diag]``, the sensor's and the actuator's records, then the reference's
    and the joint actuator's.
    """

    plant: StateLayout
    law: LawSpec
    sensor: StageSpec
    actuator: StageSpec
    reference: StageSpec = STEP_REFERENCE
    joint_actuator: StageSpec = NO_JOINT_ACTUATOR

    @property
    def law_state(self) -> slice:
        return slice(0, self.law.state_size)

    @property
    def sensor_state(self) -> slice:
        return _after(self.law_state, self.sensor.state_size)

    @property
    def actuator_state(self) -> slice:
        return _after(self.sensor_state, self.actuator.state_size)

    @property
    def reference_state(self) -> slice:
        return _after(self.actuator_state, self.reference.state_size)

    @property
    def joint_state(self) -> slice:
        return _after(self.reference_state, self.joint_actuator.state_size)

    @property
    def state_size(self) -> int:
        return self.joint_state.stop

    tau_cmd = slice(0, 3)
    tau_applied = slice(3, 6)

    @property
    def law_diag(self) -> slice:
        return _after(self.tau_applied, self.law.diag_size)

    @property
    def sensor_record(self) -> slice:
        return _after(self.law_diag, self.sensor.record_size)

    @property
    def actuator_record(self) -> slice:
        return _after(self.sensor_record, self.actuator.record_size)

    @property
    def reference_record(self) -> slice:
        return _after(self.actuator_record, self.reference.record_size)

    @property
    def joint_record(self) -> slice:
        return _after(self.reference_record, self.joint_actuator.record_size)

    @property
    def record_size(self) -> int:
        return self.joint_record.stop

    def channels(self) -> Iterator[tuple[Channel, slice]]:
        """Each declared channel of the law and the stages with its record columns."""
        for block, channels in ((self.law_diag, self.law.diagnostics),
                                (self.sensor_record, self.sensor.records),
                                (self.actuator_record, self.actuator.records),
                                (self.reference_record, self.reference.records),
                                (self.joint_record, self.joint_actuator.records)):  # fmt: skip
            start = block.start
            for channel in channels:
                yield channel, slice(start, start + channel.size)
                start += channel.size

    def __post_init__(self) -> None:
        names = [c.name for c, _ in self.channels()]
        clash = {n for n in names if names.count(n) > 1} | (set(names) & set(_LOOP_COLUMNS))
        if clash:
            raise ValueError(f"recorded channels named twice: {', '.join(sorted(clash))}")


def _after(previous: slice, size: int) -> slice:
    return slice(previous.stop, previous.stop + size)

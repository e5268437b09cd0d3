"""The FMU's slave class (pythonfmu): the open-loop stepper behind FMI 2.0.

:class:`FlexsatPlant` wraps :class:`flexsat.realtime.fmu.OpenLoopStepper`.

:func:`flexsat.realtime.fmu.export_fmu` packs this file as the FMU's script; the FMU
imports it from its resources folder, next to the satellite config, and needs
flexsat and pythonfmu in the Python that loads it (docs/realtime.md, 'The plant
as an FMU').
"""

from __future__ import annotations

import math
from xml.etree.ElementTree import Element, SubElement

import numpy as np
from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real
from pythonfmu.enums import Fmi2Status

from flexsat.dynamics.plant import Plant
from flexsat.errors import FlexsatError
from flexsat.realtime.fmu import (
    MODEL_NAME,
    UNITS,
    FmuVariable,
    OpenLoopStepper,
    fmu_variables,
    load_resources,
)

__all__ = ["FlexsatPlant"]


class _UnitReal(Real):
    """A pythonfmu Real with its FMI 2.0 ``unit`` attribute (pythonfmu writes none)."""

    def __init__(self, name: str, unit: str, **kwargs) -> None:
        super().__init__(name, **kwargs)
        self.unit = unit

    def to_xml(self) -> Element:
        node = super().to_xml()
        node.find("Real").set("unit", self.unit)
        return node


class FlexsatPlant(Fmi2Slave):
    """The open-loop flexible satellite as an FMI 2.0 co-simulation slave.

    Inputs (body torque), parameters (RK4 step, initial attitude and rate) and
    outputs (attitude, rate, tip deflection) are those of
    :func:`flexsat.realtime.fmu.fmu_variables`, each with its unit. A communication
    step must be a whole multiple of ``dt``; the inputs are held over it.

    Parameters
    ----------
    **kwargs
        pythonfmu's: ``instance_name``, ``resources`` (the folder holding the
        satellite config), ``visible``, ``logger``.
    """

    modelName = MODEL_NAME
    description = "flexsat: the open-loop flexible satellite (body torque in)"
    author = "flexsat"

    def __init__(self, **kwargs) -> None:
        super().__init__(**kwargs)
        config, dt_s = load_resources(self.resources)
        self._plant = Plant.from_config(config)
        self._variables = fmu_variables(config, dt_s)
        self._values = {v.name: v.start for v in self._variables}
        self._stepper = self._new_stepper()
        self._values |= self._stepper.outputs()
        for variable in self._variables:
            self.register_variable(self._fmi(variable))

    def _fmi(self, variable: FmuVariable) -> _UnitReal:
        name = variable.name
        causality = getattr(Fmi2Causality, variable.causality)
        extra = {}
        if variable.causality == "parameter":
            extra["variability"] = Fmi2Variability.fixed
        elif variable.causality == "input":
            extra["variability"] = Fmi2Variability.continuous

        def setter(value, name=name):
            self._values[name] = float(value)

        return _UnitReal(name, variable.unit, causality=causality,
                         description=variable.description,
                         getter=lambda: self._values[name],
                         setter=None if variable.causality == "output" else setter,
                         **extra)  # fmt: skip

    def _new_stepper(self) -> OpenLoopStepper:
        v = self._values
        return OpenLoopStepper(self._plant, v["dt"],
                               tuple(v[f"initial_{e}"] for e in ("roll", "pitch", "yaw")),
                               tuple(v[f"initial_rate_{a}"] for a in "xyz"))  # fmt: skip

    def to_xml(self, model_options: dict | None = None) -> Element:
        """The model description, with the units' FMI 2.0 ``UnitDefinitions``."""
        root = super().to_xml(model_options or {})
        definitions = Element("UnitDefinitions")
        for name, (exponents, factor) in UNITS.items():
            unit = SubElement(definitions, "Unit", name=name)
            base = {k: str(e) for k, e in exponents.items()}
            if factor != 1.0:
                base["factor"] = repr(factor)
            SubElement(unit, "BaseUnit", base)
        index = [child.tag for child in root].index("CoSimulation") + 1
        root.insert(index, definitions)
        # every output is calculated at initialization: FMI 2.0 lists them as initial
        # unknowns too (pythonfmu lists them as outputs only)
        structure = root.find("ModelStructure")
        outputs = structure.find("Outputs")
        if outputs is not None:
            initial = SubElement(structure, "InitialUnknowns")
            for unknown in outputs:
                SubElement(initial, "Unknown", index=unknown.get("index"))
        return root

    def exit_initialization_mode(self) -> None:
        """Build the plant's state from the parameters set during initialization."""
        self._stepper = self._new_stepper()
        self._values |= self._stepper.outputs()

    def do_step(self, current_time: float, step_size: float) -> bool:
        """Advance ``step_size`` [s] with the inputs held; False if it cannot."""
        torque = np.array([self._values[f"tau_{a}"] for a in "xyz"])
        if not all(math.isfinite(t) for t in torque):
            self.log(f"tau: not finite at t = {current_time:g} s", status=Fmi2Status.error)
            return False
        try:
            status = self._stepper.step(torque, step_size)
        except FlexsatError as error:
            self.log(str(error), status=Fmi2Status.error)
            return False
        self._values |= self._stepper.outputs()
        if status != 0:
            self.log(f"the plant diverged (status {status}) near t = "
                     f"{self._stepper.time_s:g} s", status=Fmi2Status.error)  # fmt: skip
            return False
        return True

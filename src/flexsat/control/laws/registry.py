"""The control-law contract: what a law declares, its compiled step, and the registry.

A law is one module that builds a :class:`LawSpec`, and one :func:`register_law`
line (for the built-ins in :mod:`flexsat.control.laws`, for a user's law in their
own file). The closed loop, the slew scenario's ``[controller]`` table,
``--controller``, the study, the report and the plots find it here; none of them
names a law.

The compiled step
-----------------
Compiled with :data:`LAW_SIGNATURE` (``@njit(LAW_SIGNATURE, cache=True)``, or
``@njit(cache=True)`` to compile it when a slew first uses it, as the built-ins do)
and called by the compiled loop
through a numba first-class function (typed by this signature, so any function of
it runs, including one defined in a user's own file)::

    status = step(q_d, omega_d, omega_dot_d, q, omega_B, J, gains, state, t, dt,
                  tau_cmd, diag)

============  ==============  ==========================================================
argument      shape           meaning
============  ==============  ==========================================================
q_d           (4,)            reference attitude quaternion, scalar first
omega_d       (3,)            reference body rate, frame B [rad/s]
omega_dot_d   (3,)            reference body acceleration, frame B [rad/s^2]
q             (4,)            measured attitude quaternion, scalar first (sensor stage)
omega_B       (3,)            measured body rate, frame B [rad/s]
J             (3, 3)          design inertia J_tot of the rigid design model [kg m^2]
gains         (n_gains,)      the law's packed gains (:meth:`LawConfig.gains`)
state         (state_size,)   the law's own state, zero at t = 0, kept between calls
t, dt         scalars         time of this control instant and control period [s]
tau_cmd       (3,)            out: commanded body torque [N m], within RF * T_max
diag          (n_diag,)       out: the declared diagnostics, in order, per-axis ones
                              as three columns (x, y, z)
============  ==============  ==========================================================

It returns 0, or a non-zero status to stop the run (reported as a failed result).
Nothing may be allocated in it. The rest-to-rest slews of the thesis have
omega_d = omega_dot_d = 0; tracking laws read them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import types
from pydantic import Field

from flexsat.config.models import _Frozen
from flexsat.control.registry import Channel, Registry

__all__ = [
    "LAWS",
    "LAW_SIGNATURE",
    "LawConfig",
    "LawSpec",
    "get_law",
    "law_names",
    "register_law",
    "validate_law_config",
]

_vec = types.float64[::1]
LAW_SIGNATURE = types.int64(
    _vec, _vec, _vec,  # reference: q_d, omega_d, omega_dot_d
    _vec, _vec,  # measurement: q, omega_B
    types.float64[:, ::1], _vec, _vec,  # J design, gains, state
    types.float64, types.float64,  # t, dt
    _vec, _vec,  # out: tau_cmd, diag
)  # fmt: skip
"""numba signature of every law's compiled step (module docstring)."""


class LawConfig(_Frozen):
    """Base of every law's parameter model (the slew scenario's ``[controller]`` table).

    A subclass declares ``kind: Literal["<name>"]``, its fields with units and
    ranges, and implements :meth:`gains`.
    """

    kind: str = Field(description="the law's registered name")

    def gains(self, actuator: Any) -> np.ndarray:
        """The packed gains the compiled step reads, float64, shape (n_gains,).

        ``actuator`` is the scenario's actuator stage config: every law keeps its
        command within the software limit ``reduction_factor * t_max_nm``.
        """
        raise NotImplementedError

    def check(self, scenario: Any) -> None:
        """Refuse a setting inconsistent with the rest of ``scenario`` (a ValueError whose
        message starts with the field's name, e.g. a controller discretized at another
        control period); default: nothing to check."""

    def plot_attributes(self) -> dict[str, float | str]:
        """What the slew plots draw for this law, written into the result's attributes.

        Keys (all optional; a law without a sliding surface returns ``{}``):
        ``surface_lambda_min_rad_s``, ``surface_lambda_max_rad_s`` (slopes of the
        sliding surface s = omega_e + Lambda q_v,e at its two ends, equal for a
        constant slope), ``boundary_layer_rad_s`` (Phi), ``jk_floor_nm`` (the robust
        gain's floor) and ``theta_threshold_deg`` (where the slope adapts).
        """
        return {}

    def linear_feedback(self, J: np.ndarray) -> np.ndarray | None:
        """The law linearized about rest, for the frequency-domain analysis.

        Parameters
        ----------
        J : ndarray, shape (3, 3)
            Design inertia J_tot [kg m^2].

        Returns
        -------
        ndarray, shape (3, 6), or None
            Static gain K of tau = -K [theta; omega] (theta the small attitude error,
            ZYX angles [rad]; omega the body rate [rad/s]); ``None`` (the default) for
            a law without a linear form about rest.
        """
        return None


@dataclass(frozen=True)
class LawSpec:
    """A control law as the loop and every consumer see it.

    Parameters
    ----------
    name : str
        The ``kind`` of its parameter table and the ``--controller`` value.
    label : str
        Display name in tables and figures (``"ASMC"``).
    config : type[LawConfig]
        Its parameter model.
    step : numba dispatcher
        The compiled step, ``@njit(LAW_SIGNATURE, cache=True)``.
    state_size : int
        Length of its state vector.
    diagnostics : tuple[Channel, ...]
        What ``diag`` holds, in order; each becomes a variable of the result.
    description : str
        One line for ``--help`` and the docs.
    """

    name: str
    label: str
    config: type[LawConfig]
    step: Any
    state_size: int
    diagnostics: tuple[Channel, ...]
    description: str = ""

    @property
    def diag_size(self) -> int:
        return sum(c.size for c in self.diagnostics)


LAWS: Registry[LawSpec] = Registry("control law", "flexsat.laws")
"""Every registered law; installed packages add theirs through ``flexsat.laws``."""


def register_law(spec: LawSpec, default: bool = False) -> LawSpec:
    """Register a law under ``spec.name`` (replacing one of that name).

    A law whose parameter model has a required field (a file to read) is registered
    but not listed by :func:`law_names`: a ``[controller]`` table selects it, the
    comparisons over every law leave it out.

    Parameters
    ----------
    spec : LawSpec
        The law.
    default : bool
        Make it the law a ``[controller]`` table without ``kind`` selects.

    Returns
    -------
    LawSpec
        ``spec``, so a module can keep it: ``X = register_law(LawSpec(...))``.
    """
    if spec.config.model_fields["kind"].default != spec.name:
        raise ValueError(f"law {spec.name!r}: its config's kind must default to {spec.name!r}")
    # a law with a required parameter (the statespace law's file) cannot run from its
    # defaults: a table names it, the every-law comparisons leave it out
    runs_alone = not any(f.is_required() for f in spec.config.model_fields.values())
    return LAWS.register(spec.name, spec, default=default, listed=runs_alone)


def get_law(name: str) -> LawSpec:
    """The registered law ``name``.

    Parameters
    ----------
    name : str
        The law's ``kind`` (``"asmc"``, ``"pd"``...).

    Returns
    -------
    LawSpec

    Raises
    ------
    ValueError
        Listing the registered laws, if none has that name.
    """
    return LAWS.get(name)


def law_names() -> tuple[str, ...]:
    """Names of every registered law that runs from its defaults, built-ins first."""
    return LAWS.names()


def validate_law_config(value: Any) -> LawConfig:
    """A ``[controller]`` table validated by its law's model (no ``kind``: the default law).

    Parameters
    ----------
    value : dict or LawConfig
        The table, or an already validated model.

    Returns
    -------
    LawConfig
        The model of the law its ``kind`` names.
    """
    return LAWS.validate_table(value, lambda spec: spec.config)

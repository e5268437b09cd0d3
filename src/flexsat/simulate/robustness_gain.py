"""An analytical estimate of the ASMC's minimum robustness gain JK_min (thesis eq. 4.21).

The sliding condition s^T J s_dot < 0 (eqs. 4.16-4.20) holds on an axis while the robust
gain JK exceeds the lumped disturbance the design model does not cancel, plus a
margin eta: JK_min >= ‖tau_dist‖_max + eta (eq. 4.21). This module bounds that
disturbance, term by term and per hub axis, from a satellite configuration and a slew
scenario (docs/control.md, "The minimum robustness gain JK_min"):

- the actuator: the torque lost to the gain G_act on a command of at most RF T_max
  (eq. 5.1), the sloshing (eq. 5.3), the constant environment (eq. 5.2) and residual
  (eq. 5.5) torques, as the scenario sets them;
- the inertia mismatch between the law's design model J_d and each truth plant's
  rigidized J_t (the Monte Carlo's +-20 % hub and panel inertia): on the applied
  torque and on the gyroscopic term at the slew's largest rate;
- the flexible torque (eq. 5.4): the step response of the linearized plant at rest,
  J_t omega_dot(0+) - tau for a torque step tau of T_max, from the hub-fixed appendage
  modes (:func:`flexsat.analysis.modal.effective_masses`' partition of M(0)).

The result is a sufficient bound for the sliding condition under the stated
assumptions, not the smallest gain that meets R1-R3: see the docs for how far apart
the two are and why.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from flexsat.config.models import SatelliteConfig
from flexsat.control.quaternion import target_quaternion
from flexsat.dynamics.plant import Plant
from flexsat.dynamics.rigid import rigid_inertia
from flexsat.errors import ConfigError
from flexsat.simulate.closedloop import slew_design_inertia
from flexsat.simulate.scenario import SlewScenario

__all__ = [
    "JKMinEstimate",
    "flexible_step_gain",
    "jk_min_estimate",
    "lumped_disturbance",
    "slew_rate_bound",
]

_THETA_SAMPLES = 20_001  # samples of theta in [0, theta_0] for the largest surface rate


@dataclass(frozen=True)
class JKMinEstimate:
    """The terms of the JK_min estimate, per hub axis (hub frame B).

    Attributes
    ----------
    actuator_nm : ndarray, shape (3,)
        ‖1 - G_act,i‖ RF T_max, the torque the actuator gain loses [N m] (eq. 5.1).
    sloshing_nm : ndarray, shape (3,)
        Sloshing ratio times RF T_max [N m] (eq. 5.3).
    environment_nm : ndarray, shape (3,)
        ‖environment torque‖ per axis [N m] (eq. 5.2).
    residual_nm : ndarray, shape (3,)
        ‖residual torque‖ per axis [N m] (eq. 5.5).
    inertia_nm : ndarray, shape (3,)
        Largest row sum of ‖J_d J_t^-1 - I‖ over the truth plants, times T_max [N m].
    gyroscopic_nm : ndarray, shape (3,)
        omega_max^2 (‖J_d - J_t‖_2 + ‖I - J_d J_t^-1‖_2 ‖J_t‖_2), largest over the
        truth plants [N m].
    flexible_nm : ndarray, shape (3,)
        Largest row sum of ‖G‖ (:func:`flexible_step_gain`) over the truth plants,
        times T_max: the flexible torque of a torque step from rest [N m].
    margin : float
        eta as a fraction of the bound (the thesis: 5 %) [-].
    budget_nm : float
        RF T_max, the most the law may command on an axis [N m].
    omega_max_rad_s : float
        The slew's largest rate the gyroscopic term is taken at [rad/s].
    """

    actuator_nm: np.ndarray
    sloshing_nm: np.ndarray
    environment_nm: np.ndarray
    residual_nm: np.ndarray
    inertia_nm: np.ndarray
    gyroscopic_nm: np.ndarray
    flexible_nm: np.ndarray
    margin: float
    budget_nm: float
    omega_max_rad_s: float

    @property
    def external_nm(self) -> np.ndarray:
        """Actuator, sloshing, environment and residual terms, shape (3,) [N m]."""
        return self.actuator_nm + self.sloshing_nm + self.environment_nm + self.residual_nm

    @property
    def disturbance_nm(self) -> np.ndarray:
        """‖tau_dist‖_max per axis, every term summed, shape (3,) [N m] (eq. 4.21)."""
        return self.external_nm + self.inertia_nm + self.gyroscopic_nm + self.flexible_nm

    @property
    def jk_min_nm(self) -> np.ndarray:
        """(1 + margin) ‖tau_dist‖_max per axis, shape (3,) [N m] (eq. 4.21)."""
        return (1.0 + self.margin) * self.disturbance_nm

    @property
    def feasible(self) -> bool:
        """True when every axis's JK_min fits within the law's budget RF T_max."""
        return bool(np.all(self.jk_min_nm <= self.budget_nm))

    def to_dict(self) -> dict:
        """JSON-ready terms (lists per axis [N m]), the totals and the verdict."""
        fields = ("actuator_nm", "sloshing_nm", "environment_nm", "residual_nm",
                  "inertia_nm", "gyroscopic_nm", "flexible_nm")  # fmt: skip
        out = {name: getattr(self, name).tolist() for name in fields}
        out.update(
            external_nm=self.external_nm.tolist(), disturbance_nm=self.disturbance_nm.tolist(),
            jk_min_nm=self.jk_min_nm.tolist(), margin=self.margin, budget_nm=self.budget_nm,
            omega_max_rad_s=self.omega_max_rad_s, feasible=self.feasible,
        )  # fmt: skip
        return out


def flexible_step_gain(plant: Plant) -> np.ndarray:
    """J_t omega_dot(0+) = (I + G) tau: the gain G of the flexible torque of a step at rest.

    At rest and undeformed, a torque step tau on the hub accelerates the hub as if the
    appendages' elastic coordinates were absent from its inertia: the hub's six
    accelerations are M_res^-1 [0; tau] with M_res = M_hh - M_hf M_ff^-1 M_fh, the
    part of M(0) no hub-fixed mode carries (:func:`flexsat.analysis.modal.effective_masses`).
    The same satellite rigidized responds with (M_hh^-1)_rr tau (J_t^-1 tau when its
    centre of mass is the hub's); the difference, as a torque on the design model J_t,
    is G tau with G = J_t ((M_res^-1)_rr - (M_hh^-1)_rr). For undamped modes it then
    oscillates between about +G tau and -G tau (the coupled modes' cosines all start
    at 1).

    Parameters
    ----------
    plant : Plant
        The satellite (its locked coordinates stay rigid).

    Returns
    -------
    ndarray, shape (3, 3)
        G, hub frame B [-]; zero for a satellite whose appendages are all locked.
    """
    M0 = plant.mass_matrix()
    locked = set(plant.locked_coordinates())
    free = [i for i in range(6, plant.n_dof) if i not in locked]
    M_res = M0[:6, :6].copy()
    if free:
        M_ff, M_fh = M0[np.ix_(free, free)], M0[free, :6]
        M_res -= M_fh.T @ np.linalg.solve(M_ff, M_fh)
    J_t = rigid_inertia(plant)
    rigid = np.linalg.inv(M0[:6, :6])[3:6, 3:6]  # nothing free: G = 0
    return J_t @ (np.linalg.inv(M_res)[3:6, 3:6] - rigid)


def slew_rate_bound(scenario: SlewScenario) -> float:
    """The largest hub rate of the slew on the ASMC's sliding surface, plus the layer.

    On the surface s = 0 the rate is Lambda q_v,e (eq. 4.6), ‖omega‖ = Lambda_target(theta)
    sin(theta / 2) with Lambda_target of eq. 4.27; its largest value over the error
    angles theta from the initial one theta_0 down to 0, plus the boundary layer's
    sqrt(3) Phi (‖s‖ inside it).

    Parameters
    ----------
    scenario : SlewScenario
        The slew; its controller must be the ASMC.

    Returns
    -------
    float
        omega_max [rad/s].
    """
    law = _asmc(scenario)
    q0 = target_quaternion(scenario.initial.attitude_deg)
    q_d = target_quaternion(scenario.target_euler_deg)
    theta0 = 2.0 * np.arccos(min(1.0, abs(float(np.dot(q0, q_d)))))
    theta = np.linspace(0.0, theta0, _THETA_SAMPLES)
    u = np.minimum(1.0, theta / np.radians(law.theta_threshold_deg))
    lam = law.lambda_max - (law.lambda_max - law.lambda_min) * u  # eq. 4.27
    rate = float(np.max(lam * np.sin(theta / 2.0)))
    return rate + np.sqrt(3.0) * law.phi + float(np.linalg.norm(np.radians(
        scenario.initial.rate_deg_s)))  # fmt: skip


def jk_min_estimate(
    satellite: SatelliteConfig,
    scenario: SlewScenario,
    truth: Sequence[SatelliteConfig] = (),
    margin: float = 0.05,
) -> JKMinEstimate:
    """Bound the ASMC's lumped disturbance, term by term, and JK_min = (1 + margin) times it.

    Parameters
    ----------
    satellite : SatelliteConfig
        The design configuration: the law's design model is its rigidized J_tot, or
        the scenario's ``design_inertia_kg_m2``.
    scenario : SlewScenario
        The slew: an ASMC controller, the actuator's T_max, RF and gain, the
        disturbances (their bounds, as "forced to maximum").
    truth : sequence of SatelliteConfig, optional
        The truth plants the law must hold (a campaign's cases); default the design
        configuration alone (no inertia mismatch).
    margin : float
        eta as a fraction of the bound, in [0, 1] (the thesis: 0.05) [-].

    Returns
    -------
    JKMinEstimate
        The terms per axis and their sum.

    Raises
    ------
    ConfigError
        The controller is not the ASMC, or ``margin`` is outside [0, 1].
    """
    _asmc(scenario)
    if not 0.0 <= margin <= 1.0:
        raise ConfigError(f"margin: must be within [0, 1], got {margin!r}")
    actuator, dist = scenario.actuator, scenario.disturbances
    t_max = actuator.t_max_nm
    command = actuator.reduction_factor * t_max  # the law's software limit
    gain = np.array(getattr(actuator, "gain", (1.0, 1.0, 1.0)), dtype=float)
    J_d = slew_design_inertia(Plant.from_config(satellite), scenario)
    omega_max = slew_rate_bound(scenario)
    inertia, gyro, flexible = np.zeros(3), np.zeros(3), np.zeros(3)
    for config in truth or (satellite,):
        plant = Plant.from_config(config)
        J_t = rigid_inertia(plant)
        mismatch = J_d @ np.linalg.inv(J_t) - np.eye(3)
        inertia = np.maximum(inertia, np.abs(mismatch).sum(axis=1) * t_max)
        # omega x J_d omega - J_d J_t^-1 (omega x J_t omega)
        #   = omega x (J_d - J_t) omega - (J_d J_t^-1 - I)(omega x J_t omega)
        bound = omega_max**2 * (np.linalg.norm(J_d - J_t, 2)
                                + np.linalg.norm(mismatch, 2) * np.linalg.norm(J_t, 2))  # fmt: skip
        gyro = np.maximum(gyro, np.full(3, bound))
        flexible = np.maximum(flexible, np.abs(flexible_step_gain(plant)).sum(axis=1) * t_max)
    return JKMinEstimate(
        actuator_nm=np.abs(1.0 - gain) * command,  # eq. 5.1
        sloshing_nm=np.full(3, dist.sloshing_ratio * command),  # eq. 5.3
        environment_nm=np.abs(np.array(dist.environment_nm, dtype=float)),  # eq. 5.2
        residual_nm=np.abs(np.array(dist.residual_nm, dtype=float)),  # eq. 5.5
        inertia_nm=inertia,
        gyroscopic_nm=gyro,
        flexible_nm=flexible,  # eq. 5.4, from the modal model
        margin=float(margin),
        budget_nm=float(command),
        omega_max_rad_s=float(omega_max),
    )


def lumped_disturbance(dataset, J_d: np.ndarray) -> np.ndarray:
    """The torque the law's design model did not predict, at every record of a slew.

    d = J_d omega_dot + omega x J_d omega - tau_cmd (eqs. 4.7, 4.18): zero for a rigid
    satellite of inertia J_d driven by its own command; the bound of
    :func:`jk_min_estimate` is a bound on ‖d_i‖.

    Parameters
    ----------
    dataset : xarray.Dataset
        A slew's records (:attr:`flexsat.simulate.Result.dataset`): ``omega``
        [rad/s], ``omega_dot`` [rad/s^2] and ``tau_cmd`` [N m], each (time, 3).
    J_d : ndarray, shape (3, 3)
        The law's design inertia, hub frame B [kg m^2].

    Returns
    -------
    ndarray, shape (n_time, 3)
        d, hub frame B [N m].
    """
    omega = np.asarray(dataset["omega"].values, dtype=float)
    omega_dot = np.asarray(dataset["omega_dot"].values, dtype=float)
    J_d = np.asarray(J_d, dtype=float)
    return omega_dot @ J_d.T + np.cross(omega, omega @ J_d.T) - dataset["tau_cmd"].values


def _asmc(scenario: SlewScenario):
    law = scenario.controller
    if law.kind != "asmc":
        raise ConfigError(f"controller.kind: the estimate is the ASMC's, got {law.kind!r}")
    return law

"""H-infinity mixed-sensitivity synthesis of an attitude controller (python-control, slycot).

The design plant is the satellite linearized about rest (attitude and body rate
from body torque), its lowest flexible modes kept by modal truncation and its
marginal part reduced to the six rigid attitude states. The generalized plant
(``docs/control.md``, "H-infinity synthesis and its weights"):

    w = [d (3), n (6)],  z = [W_p theta (3), W_u u (3), W_r omega (3)],  y = [theta; omega] + W_n n

with the disturbance torque d_max d added to the command at the plant input, and

- W_p(s) = (1/theta_R1) w_p / (s + eps w_p): the attitude error weighted by the R1
  band, its gain raised 1/eps below w_p (the constant torques must be rejected);
- W_u(s) = (1/u_max) (s/w_u + 1)/(s/(c w_u) + 1): the command weighted by the
  software limit RF T_max, rising by c = 1/(2 zeta_1) (the resonance gain of the
  least damped flexible mode) from a corner w_u a third of the first mode's
  frequency: the controller rolls off before the flexible modes;
- W_r = 1/omega_R2: the body rate weighted by the R2 band;
- W_n: sensor noise levels (the measurement is never exact: the synthesis needs it).
  The attitude noise bounds gamma from below: the loop holds the measured attitude at
  low frequency, so gamma >= n_theta / (eps theta_R1) (5.7 for the default 1e-4 rad);
  below about 1e-5 rad the solver (slycot sb10ad) does not converge on this plant
  (``docs/control.md``, "H-infinity synthesis and its weights").

``hinfsyn`` returns K with u = K y and the closed loop T_zw, ||T_zw||_inf < gamma;
gamma <= 1 means every weighted requirement holds for unit w. The controller is
then reduced by balanced truncation (:func:`flexsat.linear.reduce.balanced_truncation`)
and discretized at the control period (Tustin), in the convention of
:mod:`flexsat.control.laws.statespace`.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from flexsat.control.laws.statespace import CONTROLLER_INPUTS, DiscreteController
from flexsat.errors import ConfigError
from flexsat.linear.blas_threads import one_blas_thread
from flexsat.linear.model import LinearModel
from flexsat.linear.reduce import _split_marginal, balanced_truncation, modal_truncation

__all__ = ["HinfDesign", "HinfWeights", "design_plant", "generalized_plant", "synthesize"]

_RANK_RTOL = 1e-9  # singular values of the observability matrix below this (relative): unobservable


@dataclass(frozen=True)
class HinfWeights:
    """The synthesis weights, from the requirements (module docstring).

    Attributes
    ----------
    pointing_rad : float
        theta_R1, the R1 band [rad] (0.05 deg).
    rate_rad_s : float
        omega_R2, the R2 band [rad/s] (1e-3 deg/s).
    torque_nm : float
        u_max = RF T_max, the software torque limit [N m].
    disturbance_nm : float
        d_max, the disturbance torque bound near the target (environment + residual,
        eqs. 5.2 and 5.5) [N m].
    bandwidth_rad_s : float
        w_p, the corner of the pointing weight [rad/s].
    low_frequency_gain : float
        1/eps, the pointing weight's gain at low frequency over its gain at w_p [-].
    first_mode_rad_s : float
        omega_1, the first flexible mode's frequency [rad/s].
    modal_damping : float
        zeta_1, the least modal damping ratio [-].
    noise_rad : float
        Attitude sensor noise level [rad].
    noise_rad_s : float
        Rate sensor noise level [rad/s].
    """

    pointing_rad: float = float(np.radians(0.05))
    rate_rad_s: float = float(np.radians(1e-3))
    torque_nm: float = 1.9
    disturbance_nm: float = 0.01
    bandwidth_rad_s: float = 0.5
    low_frequency_gain: float = 50.0
    first_mode_rad_s: float = 1.62
    modal_damping: float = 0.005
    noise_rad: float = 1e-4
    noise_rad_s: float = 1e-4

    def pointing(self):
        """W_p(s), SISO ``control.TransferFunction`` [1/rad]."""
        import control

        s, wp = control.tf("s"), self.bandwidth_rad_s
        return (1.0 / self.pointing_rad) * wp / (s + wp / self.low_frequency_gain)

    def effort(self):
        """W_u(s), SISO ``control.TransferFunction`` [1/(N m)]."""
        import control

        s, wu = control.tf("s"), self.first_mode_rad_s / 3.0
        c = 1.0 / (2.0 * self.modal_damping)
        return (1.0 / self.torque_nm) * (s / wu + 1.0) / (s / (c * wu) + 1.0)


@dataclass(frozen=True, eq=False)
class HinfDesign:
    """An H-infinity design and what it achieved.

    Attributes
    ----------
    plant : LinearModel
        The design plant (attitude and rate from body torque) [rad, rad/s, N m].
    generalized : control.StateSpace
        The generalized plant P (inputs d, n, u; outputs z, y).
    controller : control.StateSpace
        The full-order continuous controller, u = K y [N m from rad, rad/s].
    gamma : float
        ||T_zw||_inf bound reported by ``hinfsyn`` [-].
    closed_loop : control.StateSpace
        T_zw with the full controller.
    reduced : control.StateSpace
        The continuous controller after balanced truncation.
    reduction_bound : float
        2 x the sum of the discarded Hankel singular values [N m/rad units].
    discrete : DiscreteController
        ``reduced`` discretized at the control period (Tustin).
    weights : HinfWeights
        The weights used.
    """

    plant: LinearModel
    generalized: object
    controller: object
    gamma: float
    closed_loop: object
    reduced: object
    reduction_bound: float
    discrete: DiscreteController
    weights: HinfWeights = field(default_factory=HinfWeights)


def design_plant(model: LinearModel, n_modes: int) -> LinearModel:
    """The synthesis plant: rigid attitude (6 states) and the ``n_modes`` lowest modes.

    Parameters
    ----------
    model : LinearModel
        The satellite about rest with outputs ``phi, theta, psi, omega_x, omega_y,
        omega_z`` and the three torque inputs (others are dropped).
    n_modes : int
        Flexible modes kept (modal truncation), >= 0.

    Returns
    -------
    LinearModel
        6 + 2 n_modes states: the marginal part's observable quotient (the hub's
        free translation, which no torque moves and no attitude output sees, is
        dropped exactly), then the kept modes.
    """
    sub = model.select(outputs=["phi", "theta", "psi", "omega_x", "omega_y", "omega_z"],
                       inputs=["tau_x", "tau_y", "tau_z"])  # fmt: skip
    n_marginal = _split_marginal(sub)[0][0].shape[0]
    order = n_marginal + 2 * n_modes
    if not n_marginal <= order < sub.n_states:
        raise ConfigError(f"modes: between 0 and {(sub.n_states - n_marginal) // 2 - 1}, "
                          f"got {n_modes}")  # fmt: skip
    red = modal_truncation(sub, order).model
    m = n_marginal
    A1, C1 = red.A[:m, :m], red.C[:, :m]
    obs = np.vstack([C1 @ np.linalg.matrix_power(A1, k) for k in range(m)])
    _, sv, Vt = np.linalg.svd(obs)
    rank = int(np.sum(sv > _RANK_RTOL * sv[0]))
    V = Vt[:rank].T  # orthonormal basis of the observable subspace (ker O is A-invariant)
    T = np.zeros((rank + red.n_states - m, red.n_states))
    T[:rank, :m] = V.T
    T[rank:, m:] = np.eye(red.n_states - m)
    Ti = T.T  # T has orthonormal rows: x = T^T z on the kept subspace
    n = T.shape[0]
    return replace(
        red, A=T @ red.A @ Ti, B=T @ red.B, C=red.C @ Ti, x0=np.zeros(n),
        state_names=tuple(f"z{k + 1}" for k in range(n)), state_units=("-",) * n,
    )  # fmt: skip


def generalized_plant(plant: LinearModel, weights: HinfWeights, input_uncertainty: float = 0.0):
    """The generalized plant P of the module docstring as a ``control.StateSpace``.

    Parameters
    ----------
    plant : LinearModel
        From :func:`design_plant` (6 outputs theta, omega; 3 torque inputs).
    weights : HinfWeights
        The weights.
    input_uncertainty : float
        r0 >= 0 [-]: when positive, an input multiplicative uncertainty channel is
        added first, ``z_I = r0 u`` and ``w_I`` summed into the torque the plant
        receives, so that ``w_I = Delta_I z_I`` makes ``u_in = (I + r0 Delta_I) u``
        (the D-K design of :mod:`flexsat.linear.dk`).

    Returns
    -------
    control.StateSpace
        Inputs ``d[0..2], n[0..5], u[0..2]``; outputs ``z1[0..2]`` (W_p theta),
        ``z2[0..2]`` (W_u u), ``z3[0..2]`` (W_r omega), ``y[0..5]``; with
        ``input_uncertainty`` > 0, inputs ``wI[0..2]`` and outputs ``zI[0..2]`` first.
    """
    import control

    I3 = np.eye(3)
    idx3, idx6 = range(3), range(6)
    G = control.ss(plant.A, plant.B, plant.C, plant.D, name="G",
                   inputs=[f"uin[{i}]" for i in idx3],
                   outputs=[f"th[{i}]" for i in idx3] + [f"w[{i}]" for i in idx3])  # fmt: skip
    uncertain = input_uncertainty > 0.0
    add = control.summing_junction(inputs=["u", "dd", "wI"] if uncertain else ["u", "dd"],
                                   output="uin", dimension=3, name="add")  # fmt: skip
    d_in, d_out = [f"d[{i}]" for i in idx3], [f"dd[{i}]" for i in idx3]
    dscale = control.ss([], [], [], weights.disturbance_nm * I3, name="dscale",
                        inputs=d_in, outputs=d_out)  # fmt: skip

    def block(sys, inp, out, name):
        m = control.ss(control.append(*[control.ss(sys)] * 3))
        return control.ss(m.A, m.B, m.C, m.D, name=name, inputs=[f"{inp}[{i}]" for i in idx3],
                          outputs=[f"{out}[{i}]" for i in idx3])  # fmt: skip

    Wp = block(weights.pointing(), "th", "z1", "Wp")
    Wu = block(weights.effort(), "u", "z2", "Wu")
    r_in, r_out = [f"w[{i}]" for i in idx3], [f"z3[{i}]" for i in idx3]
    Wr = control.ss([], [], [], I3 / weights.rate_rad_s, name="Wr",
                    inputs=r_in, outputs=r_out)  # fmt: skip
    noise = np.diag([weights.noise_rad] * 3 + [weights.noise_rad_s] * 3)
    meas = control.ss([], [], [], np.hstack([np.eye(6), noise]), name="meas",
                      inputs=[f"th[{i}]" for i in idx3] + [f"w[{i}]" for i in idx3]
                      + [f"n[{i}]" for i in idx6], outputs=[f"y[{i}]" for i in idx6])  # fmt: skip
    systems = [G, add, dscale, Wp, Wu, Wr, meas]
    inputs = [f"d[{i}]" for i in idx3] + [f"n[{i}]" for i in idx6] + [f"u[{i}]" for i in idx3]
    outputs = ([f"z1[{i}]" for i in idx3] + [f"z2[{i}]" for i in idx3]
               + [f"z3[{i}]" for i in idx3] + [f"y[{i}]" for i in idx6])  # fmt: skip
    if uncertain:
        systems.append(control.ss([], [], [], input_uncertainty * I3, name="WI",
                                  inputs=[f"u[{i}]" for i in idx3],
                                  outputs=[f"zI[{i}]" for i in idx3]))  # fmt: skip
        inputs = [f"wI[{i}]" for i in idx3] + inputs
        outputs = [f"zI[{i}]" for i in idx3] + outputs
    return control.interconnect(systems, inputs=inputs, outputs=outputs)


def _as_model(K) -> LinearModel:
    n = K.nstates
    return LinearModel(
        A=K.A, B=K.B, C=K.C, D=K.D, x0=np.zeros(n), u0=np.zeros(6), spin=np.zeros(3),
        state_names=tuple(f"k{i + 1}" for i in range(n)), input_names=CONTROLLER_INPUTS,
        output_names=("tau_x", "tau_y", "tau_z"), state_units=("-",) * n,
        input_units=("rad",) * 3 + ("rad/s",) * 3, output_units=("N m",) * 3,
        jacobian="analytic",
    )  # fmt: skip


@one_blas_thread
def synthesize(
    model: LinearModel,
    control_dt_s: float,
    order: int = 6,
    n_modes: int = 0,
    weights: HinfWeights | None = None,
) -> HinfDesign:
    """Design, reduce and discretize an H-infinity attitude controller.

    Parameters
    ----------
    model : LinearModel
        The satellite about rest (:func:`flexsat.linear.linearize`), outputs attitude
        and rate, torque inputs.
    control_dt_s : float
        The loop's control period [s]; the controller is discretized at it.
    order : int
        States of the reduced controller (balanced truncation); at most the full
        controller's order (then nothing is discarded).
    n_modes : int
        Flexible modes in the design plant; the default 0 designs against the rigid
        attitude, the roll-off of W_u keeping the modes out of the loop (robust to
        the root actuators' damping, which a design against the modes is not:
        ``docs/control.md``, "The hybrid controller").
    weights : HinfWeights, optional
        Default: :class:`HinfWeights` (the thesis's requirements).

    Returns
    -------
    HinfDesign

    Raises
    ------
    ConfigError
        If slycot is missing (the ``robust`` extra), the synthesis has no solution,
        or ``order`` is out of range.
    """
    try:
        import slycot  # noqa: F401  (hinfsyn's solver)

        import control
    except ImportError:
        raise ConfigError(
            "H-infinity synthesis needs slycot: pip install 'flexsat[robust]'"
        ) from None
    weights = weights or HinfWeights()
    plant = design_plant(model, n_modes)
    P = generalized_plant(plant, weights)
    try:
        K, CL, gamma, _ = control.hinfsyn(control.ss(P), 6, 3)
    except Exception as exc:  # slycot reports an unsolvable problem by an exception
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ConfigError(f"H-infinity synthesis failed: {reason}") from None
    if not 1 <= order <= K.nstates:
        raise ConfigError(f"order: between 1 and {K.nstates} (the full controller), got {order}")
    if order < K.nstates:
        red = balanced_truncation(_as_model(K), order)
        Kr = control.ss(red.model.A, red.model.B, red.model.C, red.model.D)
        bound = red.error_bound
    else:
        Kr, bound = control.ss(K.A, K.B, K.C, K.D), 0.0
    Kd = control.c2d(Kr, control_dt_s, method="tustin")
    discrete = DiscreteController(np.asarray(Kd.A), np.asarray(Kd.B), np.asarray(Kd.C),
                                  np.asarray(Kd.D), float(control_dt_s))  # fmt: skip
    return HinfDesign(plant, P, K, float(gamma), CL, Kr, float(bound), discrete, weights)

"""Export any appendage of a plant to the modal data format, linearized about rest.

The exact linearization about rest (:mod:`flexsat.linear.linearize`) is the plant's
M(0), K_sys and C_damp. For appendage i, with hub twist V_h = [v_hub; omega] at the
hub centre of mass and its coordinates q_i::

    T = 1/2 V_h^T M_hh,i V_h + V_h^T M_hi q_i_dot + 1/2 q_i_dot^T M_ii q_i_dot

Moving the reference to the interface point r_m (V_I = X V_h, X = [[I, -[r_m]x],
[0, I]]) gives the coupling at the interface M_Ii = X^-T M_hi, then the clamped modes
K_ii phi = omega^2 M_ii phi (mass-normalized) and the participation factors
L = phi^T M_Ii^T, all in the mount frame M. With every mode kept, the modal appendage
has the same M(0) and K_sys as the original: the same coupled frequencies
(docs/model.md, "Modal appendages").

The inertia's first-order change with the modes, J'_k = dJ_I / d eta_k, comes from
the locked inertia by central differences (it is quadratic in q: exact to round-off).
Modal damping keeps phi^T C phi whole (zeta_k = (phi^T C phi)_kk / 2 omega_k, the
off-diagonal terms, non-zero when C is not proportional, as ``damping_matrix``).

The large-motion invariants (docs/model.md, "Large motion") are derivatives of the
plant's own M(q) along the modes, the hub at rest and unrotated (there R_NB = S = I):
the translational coupling rows M_ti(q) phi = L_t(eta) and the rotational ones moved
to the interface, h(eta) = (M_ri(q) - [r_m]x M_ti(q)) phi, give C_kl = dL_t,k/d eta_l
and E_kl = dh_k/d eta_l; the locked inertia moved to the interface gives J''_kl. Each
is a central difference Richardson-extrapolated from two steps (error O(delta^4)).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import eigh

from flexsat.config.modal_data import FORMAT_VERSION, ModalData, modal_data_from_dict
from flexsat.config.models import SatelliteConfig
from flexsat.dynamics.plant import Plant

__all__ = ["large_motion_invariants", "modal_data", "modal_satellite", "mount_rotation"]

_TIP_STEP = 1e-6  # [sqrt(kg) m] central-difference step of the tip map (exact for a
# map linear + quadratic in q: the error is the cubic term, ~1e-12 relative)
# [sqrt(kg) m] steps of the large-motion invariants' differences, delta and delta / 2
# Richardson-extrapolated: truncation O(delta^4) ~ 1e-12, round-off of a second
# difference eps |M| / delta^2 ~ 1e-7 of J'' for a satellite of 1e3 kg m^2.
_SECOND_STEP = 1e-3
# Off-diagonal modal damping below this fraction of the largest entry is round-off of a
# proportional C: the export then keeps the diagonal only.
_DAMPING_RTOL = 1e-12


def mount_rotation(model, params: np.ndarray) -> np.ndarray:
    """R_BM of a packed row from the model's ``mount_rotation(params)`` (the plate, chain
    and modal models have one); identity for a model without (its data is then in B).

    Parameters
    ----------
    model : AppendageModel
        The appendage's model.
    params : ndarray, shape (p,)
        Its packed parameter row [SI].

    Returns
    -------
    ndarray, shape (3, 3)
        R_BM, mount frame M to hub frame B [-].
    """
    rotation = getattr(model, "mount_rotation", None)
    return np.eye(3) if rotation is None else np.asarray(rotation(params), dtype=float)


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _vee(A: np.ndarray) -> np.ndarray:
    return np.array([A[2, 1], A[0, 2], A[1, 0]])


def _richardson(f, step: float) -> np.ndarray:
    """(4 f(step / 2) - f(step)) / 3: a central difference of error O(step^2) made O(step^4)."""
    return (4.0 * f(0.5 * step) - f(step)) / 3.0


def large_motion_invariants(plant: Plant, appendage: str, phi: np.ndarray
                            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """The large-motion invariants of one appendage along its modes, from M(q).

    Parameters
    ----------
    plant : Plant
        The satellite.
    appendage : str
        Its name.
    phi : ndarray, shape (count, n)
        The modes: the appendage's coordinates per unit modal coordinate
        [coordinate unit / (sqrt(kg) m)].

    Returns
    -------
    C : ndarray, shape (n, n, 3)
        d^2 c~ / d eta_k d eta_l, the first moment about the interface, frame B [1/m].
    E : ndarray, shape (n, n, 3)
        d h_k / d eta_l, h_k the rotational coupling of mode k about the interface,
        frame B [-].
    J2 : ndarray, shape (n, n, 3, 3)
        d^2 J_I / d eta_k d eta_l, the inertia about the interface, frame B [-].
    """
    block = plant.layout.block(appendage)
    i = [a.name for a in plant.config.appendages].index(appendage)
    model, params, config = plant.models[i], plant.params[i], plant.config.appendages[i]
    r_m = model.shape_points(config, params, np.zeros(block.count))[4]
    R_m = _skew(r_m)
    b, n = block.slice, phi.shape[1]

    def state(eta: np.ndarray):
        q = plant.zeros()
        q[b] = phi @ eta
        M = plant.mass_matrix(q)
        L_t = (M[0:3, b] @ phi).T
        h = (M[3:6, b] @ phi).T - L_t @ R_m.T  # rows: M_ri phi_k - r_m x L_t,k
        first = _vee(-M[0:3, 3:6])  # sum of m r + c~ over the bodies, about the hub centre
        return L_t, h, first, M[3:6, 3:6]

    _, _, first_0, J_0 = state(np.zeros(n))

    def inertia_I(eta: np.ndarray) -> np.ndarray:
        # J_I(eta) - J_O(eta) = [r]x [dc]x + [dc]x [r]x + constant (parallel axes).
        _, _, first, J_O = state(eta)
        dc = _skew(first - first_0)
        return J_O - J_0 + R_m @ dc + dc @ R_m

    C, E = np.zeros((n, n, 3)), np.zeros((n, n, 3))
    for m in range(n):
        e = np.zeros(n)
        e[m] = 1.0

        def rows(step: float, e=e) -> np.ndarray:
            (tp, hp, _, _), (tm, hm, _, _) = state(step * e), state(-step * e)
            return np.concatenate([tp - tm, hp - hm], axis=1) / (2.0 * step)

        d = _richardson(rows, _SECOND_STEP)
        C[:, m], E[:, m] = d[:, :3], d[:, 3:]
    J2 = np.zeros((n, n, 3, 3))
    for k in range(n):
        for m in range(k, n):
            e_k, e_m = np.eye(n)[k], np.eye(n)[m]

            def second(step: float, e_k=e_k, e_m=e_m) -> np.ndarray:
                a, c = step * e_k, step * e_m
                return (inertia_I(a + c) - inertia_I(a - c) - inertia_I(c - a)
                        + inertia_I(-a - c)) / (4.0 * step**2)  # fmt: skip

            J2[k, m] = J2[m, k] = _richardson(second, _SECOND_STEP)
    C = 0.5 * (C + C.transpose(1, 0, 2))
    J2 = 0.5 * (J2 + J2.transpose(0, 1, 3, 2))
    return C, E, J2


def modal_data(plant: Plant, appendage: str, n_modes: int | None = None,
               large_motion: bool = True) -> ModalData:  # fmt: skip
    """The modal data of one appendage of ``plant``, linearized about rest.

    Parameters
    ----------
    plant : Plant
        The satellite.
    appendage : str
        Its name.
    n_modes : int, optional
        Modes kept, the lowest first (default: all, one per coordinate).
    large_motion : bool
        Also export the large-motion invariants (:func:`large_motion_invariants`): the
        modal appendage then keeps the modes' gyroscopic coupling and their geometric
        stiffening (docs/model.md, "Large motion").

    Returns
    -------
    ModalData
        Rigid mass properties about its root (shape point 4) and the clamped modes, in
        its mount frame; one output point ``tip`` (shape point 5).
    """
    block = plant.layout.block(appendage)
    i = [a.name for a in plant.config.appendages].index(appendage)
    model, params, config = plant.models[i], plant.params[i], plant.config.appendages[i]
    R = mount_rotation(model, params)
    R6 = np.kron(np.eye(2), R)
    at_rest = model.shape_points(config, params, np.zeros(block.count))
    r_m, tip_B = at_rest[4], at_rest[5]
    M0 = plant.mass_matrix()
    b = block.slice
    M_ii = M0[b, b]
    K_ii = np.diag(model.stiffness(params))
    C_ii = np.diag(model.damping(params))
    X_inv_T = np.eye(6)
    X_inv_T[3:, :3] = -_skew(r_m)
    M_Ii = R6.T @ X_inv_T @ M0[:6, b]  # coupling at the interface, frame M
    lam, phi = eigh(K_ii, M_ii)
    keep = block.count if n_modes is None else n_modes
    lam, phi = lam[:keep], phi[:, :keep]
    omega = np.sqrt(lam)
    damping = phi.T @ C_ii @ phi
    zeta = np.diag(damping) / (2.0 * omega)
    off = damping - np.diag(np.diag(damping))
    full = np.abs(off).max(initial=0.0) > _DAMPING_RTOL * np.abs(damping).max(initial=0.0)
    L = phi.T @ M_Ii.T
    body = model.rigid_body(params)
    c_M = R.T @ (body.r_B - r_m)
    J_I = R.T @ body.J_B @ R + body.mass * _skew(c_M).T @ _skew(c_M)
    shapes, inertia_rates = [], []
    R_skew = _skew(r_m)
    for k in range(keep):
        q = plant.zeros()
        q[b] = _TIP_STEP * phi[:, k]
        plus = plant.tip_displacement(q)[i]
        minus = plant.tip_displacement(-q)[i]
        shapes.append(((plus - minus) / (2.0 * _TIP_STEP)).tolist())
        # J'_k about the interface from the locked inertia about the hub centre of mass:
        # dJ_O = J'_k - [r]x [l_t]x - [l_t]x [r]x (parallel axes, c~ moving with eta).
        dJ_O = (plant.locked_inertia(q) - plant.locked_inertia(-q)) / (2.0 * _TIP_STEP)
        l_t = _skew(R @ L[k, :3])
        dJ = R.T @ (dJ_O + R_skew @ l_t + l_t @ R_skew) @ R
        inertia_rates.append((0.5 * (dJ + dJ.T)).tolist())
    extra = {}
    if full:
        extra["damping_matrix"] = (0.5 * (damping + damping.T)).tolist()
    if large_motion:
        C, E, J2 = large_motion_invariants(plant, appendage, phi)
        extra["first_moment_hessian"] = (C @ R).tolist()  # rows v^T R = (R^T v)^T: frame M
        extra["coupling_gradient"] = (E @ R).tolist()
        extra["inertia_hessian"] = (R.T @ J2 @ R).tolist()
    return modal_data_from_dict({
        **extra,
        "format_version": FORMAT_VERSION,
        "mass_kg": body.mass,
        "center_of_mass_m": c_M.tolist(),
        "inertia_interface_kg_m2": (0.5 * (J_I + J_I.T)).tolist(),
        "frequencies_hz": (omega / (2.0 * np.pi)).tolist(),
        "damping_ratios": zeta.tolist(),
        "participation": L.tolist(),
        "inertia_derivatives": inertia_rates,
        "output_points": [{"name": "tip", "position_m": (R.T @ (tip_B - r_m)).tolist(),
                           "mode_shapes": shapes}],
    }, source=f"export of appendage {appendage!r}")  # fmt: skip


def modal_satellite(plant: Plant, n_modes: int | None = None,
                    large_motion: bool = True) -> SatelliteConfig:  # fmt: skip
    """``plant``'s satellite with every appendage replaced by its modal export.

    Each modal appendage keeps the original's name, root point and mount frame.

    Parameters
    ----------
    plant : Plant
        The satellite.
    n_modes : int, optional
        Modes kept per appendage, the lowest first (default: all).
    large_motion : bool
        Export the large-motion invariants too (:func:`modal_data`).

    Returns
    -------
    SatelliteConfig
        The validated configuration.
    """
    from flexsat.config.load import validate_config

    tables = []
    for app in plant.config.appendages:
        i = [a.name for a in plant.config.appendages].index(app.name)
        model, params = plant.models[i], plant.params[i]
        r_m = model.shape_points(app, params, np.zeros(plant.layout.block(app.name).count))[4]
        tables.append({
            "name": app.name, "model": "modal", "mount_point_m": r_m.tolist(),
            "mount_matrix": mount_rotation(model, params).tolist(),
            "data": modal_data(plant, app.name, n_modes, large_motion).model_dump(),
        })  # fmt: skip
    data = {"name": plant.config.name, "hub": plant.config.hub.model_dump(exclude_none=True),
            "appendages": tables}  # fmt: skip
    return validate_config(data, source="modal export")

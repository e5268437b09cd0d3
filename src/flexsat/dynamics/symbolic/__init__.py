"""Reference equations of motion of the flexible satellite, derived symbolically (SymPy).

This module is the human-readable reference formulation of the dynamics: a plain
Euler-Lagrange derivation from the kinetic, potential and dissipation energies
(thesis ch. 2, eqs. 2.28-2.48, generalized to N appendages). It shares no code with
the compiled engine (:mod:`flexsat.dynamics.kernels`), which is checked against it.

Generalized coordinates, ``n = 6 + 6N``::

    q[0:3]          r        hub centre-of-mass position, inertial frame N [m]
    q[3:6]          Theta    hub ZYX Euler angles (phi, theta, psi) [rad]
    q[6+6i:9+6i]    eta_i    root translation of appendage i, mount frame M_i [m]
    q[9+6i:12+6i]   rho_i    root rotation of appendage i, ZYX angles [rad]

Kinematics (``R_NB = Rz(psi) Ry(theta) Rx(phi)`` maps hub-frame components to
inertial ones)::

    v_B     = R_NB^T r_dot                               hub velocity, frame B
    omega_B = S(phi, theta) Theta_dot                    hub rate, frame B (eq. 2.28)
    R_BM    = Rz(gamma_i) Ry(alpha_i)                    mount yaw, then SADM angle
    R_MP    = Rz(rho_z) Ry(rho_y) Rx(rho_x)              panel -> mount
    d_i     = [0, s_i L_i / 2, 0]                        root -> panel CoM, frame P
    r_G     = r_m + R_BM (eta + R_MP d)                  panel CoM in B (eq. 2.29)
    v_G     = v_B + omega_B x r_G + d/dt r_G             panel CoM velocity in B (eq. 2.30)
    omega_P = (R_BM R_MP)^T omega_B + S(rho) rho_dot     panel rate, frame P (eq. 2.31)

with ``S(a, b) = [[1, 0, -sin b], [0, cos a, cos b sin a], [0, -sin a, cos b cos a]]``.
The ``"small_angle"`` variant uses ``rho_dot`` in place of ``S(rho) rho_dot``, which
is eq. 2.31 as the thesis prints it. ``d/dt r_G`` is the exact chain-rule derivative
``(dr_G/dq) q_dot``.

Energies and equations::

    T = 1/2 m_h v_B.v_B + 1/2 omega_B.J_h omega_B
        + sum_i 1/2 m_i v_G.v_G + 1/2 omega_P.J_p omega_P        (eqs. 2.32-2.34)
    U = sum_i 1/2 q_i^T diag(k_i) q_i,  D = sum_i 1/2 q_dot_i^T diag(c_i) q_dot_i
    p = dT/dq_dot,  M = dp/dq_dot,  h = (dp/dq) q_dot - (dT/dq)^T,
    k_el = dU/dq,   C = d^2 D / dq_dot^2
    M q_ddot + h + C q_dot + k_el = Q                             (eqs. 2.37-2.48)

Every physical parameter stays a symbol, so one derivation serves every numeric
configuration with the same number of appendages. :func:`derive` returns the
symbolic model; :func:`reference_model` compiles it to plain Python (common
subexpressions eliminated) for numeric evaluation. A fresh derivation takes about
6 s, 11 s and 20 s for N = 1, 2 and 3, and code generation 1-3 s more, so both the
derived model (pickle) and the generated source are cached on disk, keyed by the
topology, the sources of this package and the SymPy and Python versions: under
``$FLEXSAT_CACHE_DIR`` or, by default, ``~/.cache/flexsat`` (see :func:`cache_dir`).
Within one process, results are memoized per topology.

One module per concern; this module wires them together and is the public entry::

    rotations    elementary rotations, ZYX Euler-rate matrix S
    symbols      parameter and coordinate symbols, topology check
    derivation   SymbolicModel and the Euler-Lagrange derivation
    printing     LaTeX and Unicode export of a model
    cache        the cache folder: location, key, atomic writes, model files
    codegen      plain-Python source of M, h, k_el, C, T and U
    reference    ReferenceParameters and ReferenceModel (numeric evaluation)
"""

from __future__ import annotations

import functools
from pathlib import Path

from flexsat.dynamics.symbolic.cache import (
    _cache_path,
    _cache_subdir,
    cache_dir,
    read_model,
    read_source,
    write_model,
    write_source,
)
from flexsat.dynamics.symbolic.cache import (
    _write_atomic as _write_atomic,  # re-exported: the cache tests write through it
)
from flexsat.dynamics.symbolic.codegen import _generate_source
from flexsat.dynamics.symbolic.derivation import SymbolicModel, _derive
from flexsat.dynamics.symbolic.reference import ReferenceModel, ReferenceParameters
from flexsat.dynamics.symbolic.rotations import (
    euler_rate_matrix,
    rot_zyx,
    rotation,
)
from flexsat.dynamics.symbolic.symbols import (
    AppendageSymbols,
    HubSymbols,
    PanelRates,
    _check_topology,
)

__all__ = [
    "AppendageSymbols",
    "HubSymbols",
    "PanelRates",
    "ReferenceModel",
    "ReferenceParameters",
    "SymbolicModel",
    "cache_dir",
    "derive",
    "euler_rate_matrix",
    "reference_model",
    "rot_zyx",
    "rotation",
]


def derive(
    n_appendages: int, panel_rates: PanelRates = "exact", *, cache: bool = True
) -> SymbolicModel:
    """Derive the equations of motion of a hub carrying ``n_appendages`` appendages.

    Parameters
    ----------
    n_appendages : int
        Number of flexible appendages N (``>= 0``).
    panel_rates : {"exact", "small_angle"}
        Panel angular velocity relative to its mount: ``"exact"`` uses
        ``S(rho) rho_dot``; ``"small_angle"`` uses ``rho_dot`` (eq. 2.31 as the
        thesis prints it). Both agree at ``rho = 0``.
    cache : bool, optional
        Reuse the model derived earlier in this process or stored in the disk
        cache (see :func:`cache_dir`), and store it there. ``False`` always derives
        afresh and touches no file.

    Returns
    -------
    SymbolicModel
        The symbols, kinematics, energies and the terms ``M, h, k_el, C_damp``.

    Notes
    -----
    A fresh derivation takes several seconds (about 6 s for N = 1, 11 s for
    N = 2, 20 s for N = 3); no simplification is attempted. The disk cache
    brings a repeated call in a new process down to a fraction of a second.
    """
    _check_topology(n_appendages, panel_rates)
    n = int(n_appendages)
    if not cache:
        return _derive(n, panel_rates)
    return _derive_cached(n, panel_rates)


@functools.cache
def _derive_cached(n_appendages: int, panel_rates: PanelRates) -> SymbolicModel:
    return _load_model(n_appendages, panel_rates, _cache_subdir())


def _load_model(
    n_appendages: int, panel_rates: PanelRates, directory: Path | None
) -> SymbolicModel:
    """The model from ``directory`` if stored there and valid, else derived and stored."""
    path = _cache_path(directory, "model", n_appendages, panel_rates, ".pickle")
    if path is not None:
        model = read_model(path)
        if (
            model is not None
            and model.n_appendages == n_appendages
            and model.panel_rates == panel_rates
        ):
            return model
    model = _derive(n_appendages, panel_rates)
    if path is not None:
        write_model(path, model)
    return model


def reference_model(
    n_appendages: int, panel_rates: PanelRates = "exact", *, cache: bool = True
) -> ReferenceModel:
    """Numeric reference model for ``n_appendages`` appendages.

    Parameters
    ----------
    n_appendages : int
        Number of appendages N.
    panel_rates : {"exact", "small_angle"}
        Panel angular-velocity variant, see :func:`derive`.
    cache : bool, optional
        Reuse the model built earlier in this process or the generated source in
        the disk cache (:func:`cache_dir`), and store it there. ``False`` derives
        and generates afresh and touches no file.

    Returns
    -------
    ReferenceModel

    Notes
    -----
    A cold build derives the model (see :func:`derive`) and generates code (about
    1 s more); with a warm disk cache it takes well under a second.
    """
    _check_topology(n_appendages, panel_rates)
    n = int(n_appendages)
    if not cache:
        return ReferenceModel(n, panel_rates, _generate_source(derive(n, panel_rates, cache=False)))
    return _reference_model_cached(n, panel_rates)


@functools.cache
def _reference_model_cached(n_appendages: int, panel_rates: PanelRates) -> ReferenceModel:
    return _load_reference(n_appendages, panel_rates, _cache_subdir())


def _load_reference(
    n_appendages: int, panel_rates: PanelRates, directory: Path | None
) -> ReferenceModel:
    """The model from the source in ``directory`` if valid, else generated and stored."""
    path = _cache_path(directory, "reference", n_appendages, panel_rates, ".py")
    source = read_source(path) if path is not None else None
    if source is not None:
        try:
            return ReferenceModel(n_appendages, panel_rates, source, path)
        except Exception:  # a damaged file: generate again and overwrite it
            pass
    source = _generate_source(derive(n_appendages, panel_rates))
    if path is not None:
        write_source(path, source)
    return ReferenceModel(n_appendages, panel_rates, source, path)

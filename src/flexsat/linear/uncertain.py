"""Uncertain linear models: the satellite about rest as an LFT in its real parameters.

The linearized eq. 2.50 about rest, ``M q_ddot + C q_dot + K q = G tau``, depends on
the thesis's uncertain parameters through M, C and K in a known way (its section
2.2.3 and the campaigns' modifiers):

- hub inertia, factor ``s_h``: ``M = M_m + s_h E J_h E^T + s_p M_p`` (E picks the
  attitude coordinates; S(0) = I so the hub's inertia enters M(0) as itself);
- panel inertia (the panel mass, so every panel term of M(0)), factor ``s_p``:
  ``M_p = M(0) - diag(m_h I_3, J_h, 0)``, and the joints re-tuned to their targets
  scale with it, ``k_j, c_j ~ s_p`` (eqs. 2.14-2.15 with J_eq ~ s_p);
- target frequency of the rotation joints (flapping, in-plane, torsion), factor
  ``s_f``: ``k_j ~ s_f^2``, ``c_j ~ s_f`` (eqs. 2.14-2.15);
- damping ratio, factor ``s_z`` of the nominal zeta: ``c_j ~ s_z``.

Each factor is affine in a normalized real parameter ``delta`` in [-1, 1],
``s = c + h delta``; the products are realized exactly as chains of such factors,
each link one repeated real scalar ``delta I_r``. Pulling every ``delta`` out gives
the LFT ``x_dot = A x + B1 w + B2 tau``, ``z = C1 x + D11 w + D12 tau``,
``y = C2 x``, ``w = Delta z``, ``Delta = diag(delta_i I_{r_i})``: the model is the
upper LFT ``F_u(P, Delta)``. The SADM angle enters M(0) through sines and cosines;
it is not pulled out but fixed per model (an analysis grids it).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from flexsat.config.models import SatelliteConfig
from flexsat.dynamics.plant import Plant
from flexsat.errors import ConfigError
from flexsat.linear.linearize import signal_names
from flexsat.linear.model import LinearModel, statespace_name

__all__ = [
    "PARAMETERS",
    "UncertainModel",
    "UncertainParameter",
    "thesis_parameters",
    "uncertain_model",
    "with_sadm_angle",
]

PARAMETERS = ("frequency", "damping", "hub_inertia", "panel_inertia")
"""The uncertain parameters an :class:`UncertainModel` can hold."""
_ROTATIONS = ("eta_rx", "eta_ry", "eta_rz")  # flapping, torsion, in-plane (plate joints)
_OUTPUTS = ("attitude", "rate", "joint")
_RANK_TOL = 1e-12  # relative eigenvalue below which M_p has no direction


@dataclass(frozen=True)
class UncertainParameter:
    """One real uncertain parameter, as a factor on its nominal value.

    Attributes
    ----------
    name : str
        One of :data:`PARAMETERS`.
    low, high : float
        Factor on the nominal value at ``delta = -1`` and ``delta = +1`` [-]
        (``frequency`` 0.8 ... 1.2 is +-20 %; ``damping`` 0 ... 1 is zeta from 0 to
        the nominal).
    """

    name: str
    low: float
    high: float

    def __post_init__(self) -> None:
        if self.name not in PARAMETERS:
            raise ConfigError(f"parameters: unknown parameter {self.name!r} "
                              f"(allowed: {', '.join(PARAMETERS)})")  # fmt: skip
        lowest = 0.0 if self.name == "damping" else 1e-3
        if not (np.isfinite(self.low) and np.isfinite(self.high)):
            raise ConfigError(f"{self.name}: the factors must be finite numbers")
        if not lowest <= self.low < self.high <= 10.0:
            raise ConfigError(
                f"{self.name}: the factor range must satisfy {lowest:g} <= low < high <= 10 "
                f"(got {self.low:g} ... {self.high:g})"
            )

    @property
    def centre(self) -> float:
        """Factor at ``delta = 0`` [-]."""
        return 0.5 * (self.low + self.high)

    @property
    def half_range(self) -> float:
        """Change of the factor per unit ``delta`` [-]."""
        return 0.5 * (self.high - self.low)

    def delta(self, factor: float) -> float:
        """The normalized ``delta`` of a factor (``+-1`` at the range's ends)."""
        return (float(factor) - self.centre) / self.half_range


def thesis_parameters() -> tuple[UncertainParameter, ...]:
    """The thesis's uncertain parameters (its section 5.2.2, the critical set).

    Returns
    -------
    tuple of UncertainParameter
        Rotation-joint target frequencies +-20 %, damping ratio 0 ... nominal, hub
        inertia +-20 %, panel inertia (mass) +-20 %.
    """
    return (
        UncertainParameter("frequency", 0.8, 1.2),
        UncertainParameter("damping", 0.0, 1.0),
        UncertainParameter("hub_inertia", 0.8, 1.2),
        UncertainParameter("panel_inertia", 0.8, 1.2),
    )


@dataclass(frozen=True, eq=False)
class UncertainModel:
    """The rest model as an upper LFT in normalized real parameters.

    ``x_dot = A x + B1 w + B2 u``, ``z = C1 x + D11 w + D12 u``, ``y = C2 x``,
    closed by ``w = Delta z`` with ``Delta = diag(delta_i I_{r_i})``, ``|delta_i| <= 1``
    the parameters' normalized values.

    Attributes
    ----------
    A, B1, B2, C1, D11, D12, C2 : ndarray
        Shapes (n_x, n_x), (n_x, n_w), (n_x, 3), (n_w, n_x), (n_w, n_w), (n_w, 3),
        (n_y, n_x). States and outputs as :func:`~flexsat.linear.linearize` names
        them; u the body torque [N m]; w, z in SI units of the force or the signal
        each channel carries.
    parameters : tuple of UncertainParameter
        The parameters, in block order.
    block_sizes : tuple of int
        r_i, the repetition of each parameter's scalar in Delta.
    channel_parameter : ndarray of int, shape (n_w,)
        Index in ``parameters`` of each channel of w and z [-].
    state_names, output_names : tuple of str
        As in :class:`~flexsat.linear.model.LinearModel`.
    translation : ndarray of int
        Indices of the hub's translation states (r_B, v_B) [-]: no force or output
        depends on them about rest, so a loop can drop them.
    sadm_angle_deg : tuple of float
        Each appendage's SADM angle the model was built at [deg].
    """

    A: np.ndarray
    B1: np.ndarray
    B2: np.ndarray
    C1: np.ndarray
    D11: np.ndarray
    D12: np.ndarray
    C2: np.ndarray
    parameters: tuple[UncertainParameter, ...]
    block_sizes: tuple[int, ...]
    channel_parameter: np.ndarray
    state_names: tuple[str, ...]
    output_names: tuple[str, ...]
    translation: np.ndarray
    sadm_angle_deg: tuple[float, ...] = field(default=())

    @property
    def n_channels(self) -> int:
        """n_w, the size of Delta."""
        return int(self.B1.shape[1])

    def delta_matrix(self, delta: Sequence[float]) -> np.ndarray:
        """Delta = diag(delta_i I_{r_i}), shape (n_w, n_w), from one value per parameter."""
        delta = np.asarray(delta, dtype=float)
        if delta.shape != (len(self.parameters),):
            raise ConfigError(f"delta: expected {len(self.parameters)} values (one per "
                              f"parameter), got shape {delta.shape}")  # fmt: skip
        return np.diag(delta[self.channel_parameter])

    def deltas(self, factors: Mapping[str, float]) -> np.ndarray:
        """Normalized deltas of factors on the nominal values, keyed by parameter name.

        A parameter not given sits at its nominal value (factor 1).
        """
        unknown = set(factors) - {p.name for p in self.parameters}
        if unknown:
            names = ", ".join(p.name for p in self.parameters)
            raise ConfigError(f"factors: unknown parameter {sorted(unknown)[0]!r} "
                              f"(allowed: {names})")  # fmt: skip
        return np.array([p.delta(factors.get(p.name, 1.0)) for p in self.parameters])

    def nominal_delta(self) -> np.ndarray:
        """The deltas of the nominal satellite (every factor 1)."""
        return self.deltas({})

    def evaluate(self, delta: Sequence[float]) -> LinearModel:
        """The model at one parameter point: the upper LFT closed by Delta.

        Parameters
        ----------
        delta : sequence of float, length len(parameters)
            Normalized parameter values (any real; the analysis box is [-1, 1]).

        Returns
        -------
        LinearModel
            ``A + B1 Delta (I - D11 Delta)^-1 C1`` and its input and output matrices;
            inputs the body torque, outputs :attr:`output_names`.
        """
        Dl = self.delta_matrix(delta)
        X = np.linalg.solve(np.eye(self.n_channels) - Dl @ self.D11, Dl)  # (I - Delta D11)^-1 Delta
        A = self.A + self.B1 @ X @ self.C1
        B = self.B2 + self.B1 @ X @ self.D12
        n_y = self.C2.shape[0]
        n = self.A.shape[0]
        return LinearModel(
            A=A, B=B, C=self.C2.copy(), D=np.zeros((n_y, 3)), x0=np.zeros(n), u0=np.zeros(3),
            spin=np.zeros(3), state_names=self.state_names,
            input_names=("tau_x", "tau_y", "tau_z"), output_names=self.output_names,
            state_units=("",) * n, input_units=("N m",) * 3, output_units=("",) * n_y,
            jacobian="analytic",
        )  # fmt: skip

    def channel_names(self) -> tuple[str, ...]:
        """One name per channel of w (and z): ``<parameter>_<k>``."""
        counts: dict[int, int] = {}
        names = []
        for i in self.channel_parameter:
            counts[i] = counts.get(i, 0) + 1
            names.append(f"{self.parameters[i].name}_{counts[i]}")
        return tuple(names)

    def to_statespace(self):
        """The LFT's plant P as a ``control.StateSpace``: inputs [w, tau], outputs [z, y].

        Closing its first n_w outputs to its first n_w inputs through Delta
        (``control.feedback`` with a static Delta, positive feedback) gives the model
        at that parameter point.
        """
        import control

        A, B, C, D = self.plant_matrices()
        ch = self.channel_names()
        return control.ss(
            A, B, C, D, states=list(self.state_names),
            inputs=[f"w_{c}" for c in ch] + ["tau_x", "tau_y", "tau_z"],
            outputs=[f"z_{c}" for c in ch] + [statespace_name(n) for n in self.output_names],
            name="flexsat_lft",
        )  # fmt: skip

    def plant_matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """P's A, B = [B1 B2], C = [C1; C2], D = [[D11, D12], [0, 0]]."""
        n_y = self.C2.shape[0]
        B = np.hstack([self.B1, self.B2])
        C = np.vstack([self.C1, self.C2])
        D = np.block([[self.D11, self.D12], [np.zeros((n_y, self.n_channels + 3))]])
        return self.A, B, C, D

    def save_mat(self, path: str | Path) -> Path:
        """Write P and its block structure to a MATLAB ``.mat`` (v5).

        Variables: ``A, B, C, D`` of :meth:`plant_matrices`; ``block_names``,
        ``block_sizes``, ``block_low``, ``block_high`` (the factor range of each
        parameter); ``channel_names``, ``state_names``, ``output_names`` (cell arrays).
        In MATLAB, ``delta_i = ureal(name, 0, 'Range', [-1 1])`` and
        ``lft(blkdiag(delta_i * eye(r_i), ...), ss(A, B, C, D))`` rebuild the model.
        """
        from scipy.io import savemat

        from flexsat.files import replacing

        A, B, C, D = self.plant_matrices()
        cells = {
            "block_names": [p.name for p in self.parameters],
            "channel_names": list(self.channel_names()),
            "state_names": list(self.state_names),
            "output_names": list(self.output_names),
        }
        data = {k: np.array(v, dtype=object).reshape(-1, 1) for k, v in cells.items()}
        data.update(A=A, B=B, C=C, D=D, block_sizes=np.array(self.block_sizes, dtype=float),
                    block_low=np.array([p.low for p in self.parameters]),
                    block_high=np.array([p.high for p in self.parameters]))  # fmt: skip
        path = Path(path)
        with replacing(path) as handle:
            savemat(handle, data, oned_as="column")
        return path


def with_sadm_angle(config: SatelliteConfig, angle_deg: float) -> SatelliteConfig:
    """The satellite with every plate's SADM angle set to one value.

    Parameters
    ----------
    config : SatelliteConfig
        The satellite; its plates' other settings are kept.
    angle_deg : float
        The SADM angle of every plate [deg].

    Returns
    -------
    SatelliteConfig
        A validated copy.
    """
    from flexsat.config.load import validate_config

    data = config.model_dump()
    for app in data["appendages"]:
        app["sadm_angle_deg"] = float(angle_deg)
    return validate_config(data)


class _Chains:
    """Channel bookkeeping: each link ``delta z`` of a chain of affine factors."""

    def __init__(self, n_cols: int, parameters: Sequence[UncertainParameter]):
        self.n_cols = n_cols  # columns [x, u]; w columns appended as channels open
        self.parameters = list(parameters)
        self.z_rows: list[tuple[int, list | None]] = []  # per link: first channel, terms
        self.owner: list[int] = []

    def open(self, name: str, size: int, terms: list | None) -> tuple[int, int]:
        """Open ``size`` channels of parameter ``name``; their slice of w.

        ``terms`` is what z reads (a chain's running product), ``None`` for a mass
        link, whose z reads q_ddot and is filled in later.
        """
        k = next(i for i, p in enumerate(self.parameters) if p.name == name)
        start = len(self.owner)
        self.z_rows.append((start, terms))
        self.owner += [k] * size
        return start, start + size

    def factor(self, name: str) -> tuple[float, float]:
        """(c, h) of the factor ``c + h delta`` of a parameter (1, 0 when not uncertain)."""
        p = next((p for p in self.parameters if p.name == name), None)
        return (1.0, 0.0) if p is None else (p.centre, p.half_range)

    def chain(self, signal: np.ndarray, gain: np.ndarray, names: Sequence[str]):
        """Rows of ``gain * prod(c + h delta)`` applied to ``signal``, and its links.

        Returns the output's rows (as a list of terms: the x/u part and, per link, a
        w slice and its coefficient) to be assembled once every channel is known.
        """
        terms = [(None, np.diag(gain) @ signal)]  # cur = sum of terms
        for name in names:
            c, h = self.factor(name)
            if h == 0.0:
                terms = [(s, c * m) for s, m in terms]
                continue
            links = self.open(name, signal.shape[0], terms)
            terms = [(s, c * m) for s, m in terms] + [(links, h * np.eye(signal.shape[0]))]
        return terms


def uncertain_model(
    config: SatelliteConfig,
    parameters: Sequence[UncertainParameter] | None = None,
    outputs: Sequence[str] = ("attitude", "rate"),
) -> UncertainModel:
    """The satellite's rest model as an LFT in its uncertain parameters.

    Parameters
    ----------
    config : SatelliteConfig
        The nominal satellite; every appendage a plate without a drive (the SADM
        angle fixed at the config's value).
    parameters : sequence of UncertainParameter, optional
        Default :func:`thesis_parameters`. Each name at most once. The same factor
        applies to every appendage.
    outputs : sequence of str
        Output groups among ``attitude``, ``rate``, ``joint`` (their C does not depend
        on the parameters).

    Returns
    -------
    UncertainModel
        At the nominal deltas (:meth:`UncertainModel.nominal_delta`) it is the
        nominal :func:`~flexsat.linear.linearize` model's A and B; at any point, the
        model of the satellite whose parameters the campaign modifiers change by the
        same factors.

    Raises
    ------
    ConfigError
        An appendage that is not a plate or is on a drive, a parameter named twice,
        an unknown output group.
    """
    parameters = tuple(thesis_parameters() if parameters is None else parameters)
    names = [p.name for p in parameters]
    if len(set(names)) != len(names):
        raise ConfigError(f"parameters: each parameter at most once (got {', '.join(names)})")
    for g in outputs:
        if g not in _OUTPUTS:
            raise ConfigError(f"outputs: unknown output {g!r} (allowed: {', '.join(_OUTPUTS)})")
    for k, app in enumerate(config.appendages):
        if app.model != "plate" or getattr(app, "drive", None) is not None:
            raise ConfigError(
                f"appendages[{k}]: an uncertain model is built for plates on a fixed SADM "
                f"angle; {app.name!r} is a {app.model!r}"
                + (" on a drive" if getattr(app, "drive", None) is not None else "")
            )
    plant = Plant.from_config(config)
    n = plant.n_dof
    M0 = plant.mass_matrix()
    J_h = plant.hub_J
    E = np.zeros((n, 3))
    E[3:6] = np.eye(3)
    M_m = np.zeros((n, n))
    M_m[0:3, 0:3] = plant.hub_mass * np.eye(3)
    M_J = E @ J_h @ E.T
    M_p = M0 - M_m - M_J  # every panel term of M(0): proportional to the panel mass
    lam, U = np.linalg.eigh(M_p)
    keep = np.abs(lam) > _RANK_TOL * np.max(np.abs(lam))
    lam, U = lam[keep], U[:, keep]
    stiffness = np.diag(plant.stiffness_matrix())
    damping = np.diag(plant.damping_matrix())
    dof = plant.layout.dof_names()
    rot = np.array([i for i in range(6, n) if dof[i].split(".")[-1] in _ROTATIONS])
    trans = np.array([i for i in range(6, n) if i not in set(rot)])

    n_u = 3
    cols = 2 * n + n_u  # [q, q_dot, u]
    sel_q, sel_qd = np.eye(cols)[:n], np.eye(cols)[n : 2 * n]
    ch = _Chains(cols, parameters)
    # Joint forces: k_j q_j and c_j q_dot_j through their chains of factors (eqs. 2.14-2.15).
    force_terms = []  # (rows of q, terms)
    chains = (
        (rot, ("panel_inertia", "frequency", "frequency"),
         ("panel_inertia", "damping", "frequency")),
        (trans, ("panel_inertia",), ("panel_inertia", "damping")),
    )  # fmt: skip
    for idx, factors_k, factors_c in chains:
        if idx.size == 0:
            continue
        force_terms.append((idx, ch.chain(sel_q[idx], stiffness[idx], factors_k)))
        force_terms.append((idx, ch.chain(sel_qd[idx], damping[idx], factors_c)))
    # Mass: the centre M_c, and the hub's and panels' parts through one link each.
    c_h, h_h = ch.factor("hub_inertia")
    c_p, h_p = ch.factor("panel_inertia")
    M_c = M_m + c_h * M_J + c_p * M_p
    mass_links = []  # (w slice, force map)
    hub_rows = (J_h @ E.T) if h_h else None
    panel_rows = (lam[:, None] * U.T) if h_p else None
    # z of a mass link reads q_ddot, known once every channel is: open them now (rows later).
    if hub_rows is not None:
        mass_links.append((ch.open("hub_inertia", 3, None), h_h * E, hub_rows))
    if panel_rows is not None:
        mass_links.append((ch.open("panel_inertia", lam.size, None), h_p * U, panel_rows))
    n_w = len(ch.owner)
    width = cols + n_w

    def expand(terms) -> np.ndarray:
        """Rows over [q, q_dot, u, w] of a chain's terms."""
        out = None
        for s, m in terms:
            block = np.zeros((m.shape[0], width))
            if s is None:
                block[:, :cols] = m
            else:
                block[:, cols + s[0] : cols + s[1]] = m
            out = block if out is None else out + block
        return out

    # M_c q_ddot = G u - sum of joint forces - sum of mass links (h E w_h, h U w_p).
    rhs = np.zeros((n, width))
    rhs[3:6, 2 * n : 2 * n + 3] = np.eye(3)  # Q_Theta = S(0)^T tau = tau
    for idx, terms in force_terms:
        rhs[idx] -= expand(terms)
    for (s0, s1), fmap, _ in mass_links:
        rhs[:, cols + s0 : cols + s1] -= fmap
    qdd = np.linalg.solve(M_c, rhs)
    # z rows: the chains' links as recorded (padded to the full width), the mass links'
    # readings of q_ddot.
    Z = np.zeros((n_w, width))
    for start, terms in ch.z_rows:
        if terms is not None:  # a chain link reads the running product
            rows = expand(terms)
            Z[start : start + rows.shape[0]] = rows
    for (s0, s1), _, read in mass_links:
        Z[s0:s1] = read @ qdd
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:] = qdd[:, : 2 * n]
    B2 = np.vstack([np.zeros((n, 3)), qdd[:, 2 * n : cols]])
    B1 = np.vstack([np.zeros((n, n_w)), qdd[:, cols:]])
    names = signal_names(plant)
    out_names = tuple(s for g in outputs for s in names[g][0])
    state_index = {s: i for i, s in enumerate(names["states"][0])}
    C2 = np.zeros((len(out_names), 2 * n))
    for i, s in enumerate(out_names):
        C2[i, state_index[s]] = 1.0
    owner = np.array(ch.owner, dtype=np.int64)
    return UncertainModel(
        A=A, B1=B1, B2=B2, C1=Z[:, : 2 * n], D11=Z[:, cols:], D12=Z[:, 2 * n : cols], C2=C2,
        parameters=parameters,
        block_sizes=tuple(int(np.sum(owner == k)) for k in range(len(parameters))),
        channel_parameter=owner, state_names=names["states"][0], output_names=out_names,
        translation=np.r_[0:3, n : n + 3],
        sadm_angle_deg=tuple(float(getattr(a, "sadm_angle_deg", 0.0)) for a in config.appendages),
    )  # fmt: skip

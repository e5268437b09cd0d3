"""The linear state-space model of the satellite and its files (NPZ, MATLAB ``.mat``).

A :class:`LinearModel` holds ``x_dot = A x + B u``, ``y = C x + D u`` about an
equilibrium, with a name (and unit) for every state, input and output. It converts
to a ``control.StateSpace`` of python-control and writes plain arrays for users who
continue elsewhere. The variable names in both files are the same:

=================== ===================================================================
name                content
=================== ===================================================================
``A``               (n_x, n_x) state matrix
``B``               (n_x, n_u) input matrix
``C``               (n_y, n_x) output matrix
``D``               (n_y, n_u) feedthrough matrix
``x0``              (n_x,) equilibrium state (body-frame variables, SI)
``u0``              (n_u,) equilibrium input (the torque holding a spin, zero at rest) [SI]
``spin``            (3,) body rate of the reference motion, hub frame B [rad/s]
``state_names``     names, one string per row (likewise ``input_names``, ``output_names``)
``state_units``     SI units of each (likewise ``input_units``, ``output_units``)
=================== ===================================================================
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from flexsat.errors import ConfigError

__all__ = ["MAT_VARIABLES", "LinearModel", "statespace_name"]

_BATCH = 256  # frequencies solved at once (stacked LAPACK calls)

MAT_VARIABLES = (
    "A", "B", "C", "D", "x0", "u0", "spin",
    "state_names", "input_names", "output_names",
    "state_units", "input_units", "output_units",
)  # fmt: skip


@dataclass(frozen=True, eq=False)
class LinearModel:
    """``x_dot = A x + B u``, ``y = C x + D u`` about an equilibrium, with named signals.

    Attributes
    ----------
    A, B, C, D : ndarray
        Shapes (n_x, n_x), (n_x, n_u), (n_y, n_x), (n_y, n_u) [SI: the units of the named signals].
    x0 : ndarray, shape (n_x,)
        The equilibrium (perturbations are about it) [SI, ``state_units``].
    u0 : ndarray, shape (n_u,)
        Input at the equilibrium [N m].
    spin : ndarray, shape (3,)
        Body rate of the reference motion, hub frame B [rad/s]; zero at rest.
    state_names, input_names, output_names : tuple of str
        Name of each state, input and output.
    state_units, input_units, output_units : tuple of str
        SI unit of each.
    jacobian : str
        How A, B were obtained: ``"analytic"`` or ``"richardson"``.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    x0: np.ndarray
    u0: np.ndarray
    spin: np.ndarray
    state_names: tuple[str, ...]
    input_names: tuple[str, ...]
    output_names: tuple[str, ...]
    state_units: tuple[str, ...]
    input_units: tuple[str, ...]
    output_units: tuple[str, ...]
    jacobian: str

    @property
    def n_states(self) -> int:
        return int(self.A.shape[0])

    def poles(self) -> np.ndarray:
        """Eigenvalues of A [rad/s], sorted by imaginary part then real part."""
        lam = np.linalg.eigvals(self.A)
        return lam[np.lexsort((lam.real, lam.imag))]

    def select(
        self, outputs: list[str] | None = None, inputs: list[str] | None = None
    ) -> LinearModel:
        """The same model keeping only the named outputs and inputs (in the order given).

        Raises
        ------
        ConfigError
            If a name is not an output (input) of the model; the message lists them.
        """
        rows = _indices(outputs, self.output_names, "outputs")
        cols = _indices(inputs, self.input_names, "inputs")
        return replace(
            self,
            B=self.B[:, cols],
            C=self.C[rows],
            D=self.D[np.ix_(rows, cols)],
            u0=self.u0[cols],
            input_names=tuple(self.input_names[j] for j in cols),
            input_units=tuple(self.input_units[j] for j in cols),
            output_names=tuple(self.output_names[i] for i in rows),
            output_units=tuple(self.output_units[i] for i in rows),
        )

    def frequency_response(self, frequencies_hz: np.ndarray) -> np.ndarray:
        """G(i 2 pi f) = C (i 2 pi f I - A)^-1 B + D, shape (n_f, n_y, n_u), SI units."""
        f = np.atleast_1d(np.asarray(frequencies_hz, dtype=float))
        eye = np.eye(self.n_states)
        out = np.empty((f.size, self.C.shape[0], self.B.shape[1]), dtype=complex)
        for k in range(0, f.size, _BATCH):
            s = 2j * np.pi * f[k : k + _BATCH, None, None]
            X = np.linalg.solve(
                s * eye - self.A, np.broadcast_to(self.B, (s.shape[0], *self.B.shape))
            )
            out[k : k + _BATCH] = self.C @ X + self.D
        return out

    def to_statespace(self):
        """The model as a ``control.StateSpace`` with the signal names attached.

        python-control keeps the dot for a subsystem's signal in an interconnection
        and refuses it in an input or output name, so there each ``.`` of a name
        becomes ``_`` (:func:`statespace_name`: ``panel_1.tip_x`` -> ``panel_1_tip_x``);
        state names are kept as they are.
        """
        import control

        return control.ss(
            self.A, self.B, self.C, self.D,
            states=list(self.state_names),
            inputs=[statespace_name(n) for n in self.input_names],
            outputs=[statespace_name(n) for n in self.output_names], name="flexsat",
        )  # fmt: skip

    def to_dict(self) -> dict:
        """Arrays and names keyed as in :data:`MAT_VARIABLES`."""
        return {name: getattr(self, name) for name in MAT_VARIABLES}

    def save_npz(self, path: str | Path) -> Path:
        """Write the model to a NumPy ``.npz`` (variables of :data:`MAT_VARIABLES`)."""
        from flexsat.files import replacing

        path = Path(path)
        arrays = {k: np.asarray(v) for k, v in self.to_dict().items()}
        with replacing(path) as handle:  # a link at path is replaced, never followed
            np.savez(handle, **arrays)
        return path

    def save_mat(self, path: str | Path) -> Path:
        """Write the model to a MATLAB ``.mat`` (v5, ``scipy.io.savemat``).

        Names are stored as cell arrays of strings, so in MATLAB
        ``sys = ss(A, B, C, D, 'StateName', state_names, ...)`` works directly.
        """
        from scipy.io import savemat

        from flexsat.files import replacing

        path = Path(path)
        data = {}
        for key, value in self.to_dict().items():
            if key.endswith(("_names", "_units")):
                data[key] = np.array(value, dtype=object).reshape(-1, 1)
            else:
                data[key] = np.asarray(value, dtype=float)
        with replacing(path) as handle:  # a link at path is replaced, never followed
            savemat(handle, data, oned_as="column")
        return path


def statespace_name(name: str) -> str:
    """An input or output name as python-control accepts it: each ``.`` made ``_``.

    Parameters
    ----------
    name : str
        A signal name of a :class:`LinearModel` (``"panel_1.tip_x"``).

    Returns
    -------
    str
        ``"panel_1_tip_x"``.
    """
    return name.replace(".", "_")


def _indices(names: list[str] | None, allowed: tuple[str, ...], what: str) -> list[int]:
    if names is None:
        return list(range(len(allowed)))
    if not names:
        raise ConfigError(f"{what}: give at least one name (allowed: {', '.join(allowed)})")
    unknown = [n for n in names if n not in allowed]
    if unknown:
        raise ConfigError(f"{what}: unknown name {unknown[0]!r} (allowed: {', '.join(allowed)})")
    return [allowed.index(n) for n in names]

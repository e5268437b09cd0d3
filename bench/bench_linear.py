"""Benchmark: time to linearize the thesis model, analytic against finite differences.

Rows (nominal two-panel satellite, 18 DOF, 36 states; best of ``REPEATS`` after one
warm-up call that loads the compiled kernels):

* about rest, analytic A, B (M(0), K, C) plus the output matrices by differences;
* about rest with Richardson central differences for A, B as well;
* about a steady spin (1 rad/s about body X): the relative equilibrium (Gauss-Newton)
  and Richardson differences;
* balanced truncation of the torque -> rate model to 16 states; the PD loop margins
  of the three axes;
* the ``chain`` preset with each panel as a 32-segment chain (3 rotational DOFs per
  joint: 198 DOF, 396 states), about rest, analytic against Richardson differences.

The agreement of the two rest Jacobians (max |A_fd - A_exact| / max |A|) is printed
with them. Run with ``python bench/bench_linear.py``.
"""

from __future__ import annotations

import numpy as np

import harness
from flexsat.config import load_config, nominal, preset_path
from flexsat.dynamics.plant import Plant
from flexsat.linear import linearize
from flexsat.linear.frequency import loop_margins, pd_gains, pd_loop
from flexsat.linear.reduce import balanced_truncation

REPEATS = 5


def _best(fn) -> tuple[float, object]:
    """Best of :data:`REPEATS` after a warm-up call [s], and the last call's value."""
    return harness.best_of(fn, REPEATS, warm_up=True)


@harness.register(
    "linearizing the thesis model (analytic and by differences, about rest and a steady "
    "spin), balanced truncation, margins, and a 198-DOF chain model",
    full=False,
)
def main() -> None:
    plant = Plant.from_config(nominal())
    rows = []
    t_exact, exact = _best(lambda: linearize(plant))
    rows.append(("rest, analytic A, B", t_exact, ""))
    t_fd, fd = _best(lambda: linearize(plant, jacobian="richardson"))
    err = np.max(np.abs(fd.A - exact.A)) / np.max(np.abs(exact.A))
    rows.append(("rest, Richardson A, B", t_fd, f"max rel. diff. to analytic {err:.1e}"))
    t_spin, _ = _best(lambda: linearize(plant, about=[1.0, 0.0, 0.0]))
    rows.append(("spin 1 rad/s about X (equilibrium + Richardson)", t_spin, ""))
    rate = exact.select(outputs=["omega_x", "omega_y", "omega_z"])
    t_bt, red = _best(lambda: balanced_truncation(rate, 16))
    rows.append(("balanced truncation to 16 states", t_bt, f"bound {red.error_bound:.3g}"))
    K = pd_gains(plant)
    t_m, _ = _best(lambda: [loop_margins(pd_loop(exact, K, a)) for a in "xyz"])
    rows.append(("PD loop margins, 3 axes", t_m, ""))
    chain = _chain_plant(32)
    t_chain, chain_exact = _best(lambda: linearize(chain))
    rows.append((f"2 x 32-segment chains, rest, analytic ({chain_exact.n_states} states)",
                 t_chain, ""))  # fmt: skip
    t_chain_fd, chain_fd = _best(lambda: linearize(chain, jacobian="richardson"))
    err = np.max(np.abs(chain_fd.A - chain_exact.A)) / np.max(np.abs(chain_exact.A))
    rows.append(("2 x 32-segment chains, rest, Richardson", t_chain_fd,
                 f"max rel. diff. to analytic {err:.1e}"))  # fmt: skip
    table = harness.table(
        f"Linear analysis, nominal satellite ({exact.n_states} states)",
        ("what", "time [ms]", "note"),
        right=(),
    )
    for what, t, note in rows:
        table.add_row(what, f"{1e3 * t:.2f}", note)
    harness.console().print(table)


def _chain_plant(segments: int) -> Plant:
    """The ``chain`` preset with ``segments`` segments per panel."""
    config = load_config(preset_path("chain"))
    data = config.model_dump(mode="json")
    for appendage in data["appendages"]:
        appendage["segments"] = segments
    return Plant.from_config(type(config).model_validate(data))


if __name__ == "__main__":
    main()

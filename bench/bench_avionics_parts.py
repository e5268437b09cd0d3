"""Benchmark: what each piece of the avionics chain adds to a plant step, measured apart.

``bench/bench_avionics.py`` times whole 120 s slews; on a shared virtual machine its
best-of figures move by 10 % from one run to the next, more than the pieces it is
meant to separate. This one times the pieces in compiled loops of ``--calls`` calls
each and keeps the minimum over ``--batches`` batches, which preemption only
lengthens. Within one run the pieces are comparable; from one run to the next the
whole machine's speed can still move (by up to 20 % on the 2-core virtual machine
of ``CHANGELOG.md``, "The coupled step's pieces"), so compare runs by their
ratios, and repeat:

- one RK4 step of the nominal plant (``rk4_step``), the ideal loop's step;
- the coupled RK4 step (``rk4_coupled_step``) with a derivative that does nothing,
  then with the four-wheel pyramid: the coupling's own cost, then the wheels';
- the sensing chain at one control instant (``run_sensors``): the ideal sensor alone,
  then with the gyro, the star tracker and the MEKF after it, as the avionics slew
  runs them (the rate changes at every instant, so the gyro's samples move).

Nanoseconds per call; the last column is the piece's share of the ideal step.
"""

from __future__ import annotations

import argparse

import numpy as np
from numba import njit

import harness
from flexsat import Plant, nominal
from flexsat.compiled.first_class import first_class
from flexsat.compiled.no_refcount import borrowed
from flexsat.control.stages.registry import DERIVATIVE_SIGNATURE, no_derivative
from flexsat.dynamics.integrators import rk4_step
from flexsat.simulate import SlewScenario
from flexsat.simulate.closedloop import prepare_slew
from flexsat.simulate.coupled import rk4_coupled_step
from flexsat.simulate.loops import run_sensors

DT = 1e-3  # RK4 step [s]
SENSING = [{"kind": "gyro"}, {"kind": "star_tracker"}, {"kind": "mekf"}]


@njit
def _plant_steps(x, n_steps, n, Q, scratch, torque, packed):
    for _ in range(n_steps):
        rk4_step(x, DT, torque, n, Q, scratch, packed)


@njit
def _coupled_steps(x, n_steps, n, Q, scratch, derivatives, params, flow, packed):
    for k in range(n_steps):
        rk4_coupled_step(x, k * DT, DT, n, Q, scratch, derivatives, params, flow, packed, False)


@njit
def _sense(x, n_steps, n, stages, d):
    x, d = borrowed((x, d))  # as the loop hands them over
    for k in range(n_steps):
        x[n + 3] += 1e-7  # the body rate moves: the gyro's samples change
        run_sensors(x, n, k * DT, stages, d)


def _best(call, x0: np.ndarray, calls: int, batches: int) -> float:
    """Minimum over the batches of one call's time [ns]; each batch from ``x0``."""
    call(x0.copy(), 2)  # compile
    best, _ = harness.best_of(lambda x: call(x, calls), batches, setup=x0.copy)
    return best / calls * 1e9


@harness.register(
    "the avionics chain's pieces apart, in compiled loops (minimum of many batches): the RK4 "
    "plant step, the coupled step with an idle derivative and with the wheels, the sensing "
    "chain stage by stage"
)
def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calls", type=int, default=2000, help="calls per batch")
    parser.add_argument("--batches", type=int, default=150, help="batches (minimum kept)")
    args = parser.parse_args(argv)
    plant = Plant.from_config(nominal())
    n, packed = plant.n_dof, plant.packed
    wheels = prepare_slew(plant, SlewScenario(actuator={"kind": "wheels"}))
    x0 = wheels.x.copy()
    x0[3:6] = (0.1, 0.2, 0.3)  # mid-slew: attitude, rates and wheel momenta not zero
    x0[n + 3 : n + 6] = (0.01, -0.02, 0.015)
    data, stages = wheels.data, wheels.stages
    data.flow.held[:] = (0.1, -0.2, 0.05)
    data.flow.state[:4] = (0.3, -0.2, 0.1, 0.05)
    scratch, Q, torque = np.empty((5, x0.shape[0])), np.zeros(n), (0.1, -0.2, 0.05)
    # padded like the loop's chain (flexsat.simulate.loops.CHAIN_SLOTS): the same type
    idle = (first_class(no_derivative, DERIVATIVE_SIGNATURE),) * len(stages.derivative)
    params = data.actuator_params
    ns = {
        "RK4 plant step (ideal loop)": _best(
            lambda x, c: _plant_steps(x, c, n, Q, scratch, torque, packed), x0, args.calls,
            args.batches),
        "coupled step, idle derivative": _best(
            lambda x, c: _coupled_steps(x, c, n, Q, scratch, idle, params, data.flow, packed),
            x0, args.calls, args.batches),
        "coupled step, four wheels": _best(
            lambda x, c: _coupled_steps(x, c, n, Q, scratch, stages.derivative, params,
                                        data.flow, packed), x0, args.calls, args.batches),
    }  # fmt: skip
    chain: list[dict] = []
    for name, stage in [("ideal sensor", None), ("+ gyro", SENSING[0]),
                        ("+ star tracker", SENSING[1]), ("+ MEKF", SENSING[2])]:  # fmt: skip
        chain = chain + ([stage] if stage else [])
        run = prepare_slew(plant, SlewScenario(sensor_stages=chain))
        ns[f"sensing: {name}"] = _best(
            lambda x, c, run=run: _sense(x, c, n, run.stages, run.data), x0, args.calls * 5,
            args.batches)  # fmt: skip
    step = ns["RK4 plant step (ideal loop)"]
    against = {  # each piece against the one it adds to
        "coupled step, idle derivative": "RK4 plant step (ideal loop)",
        "coupled step, four wheels": "coupled step, idle derivative",
        "sensing: + gyro": "sensing: ideal sensor",
        "sensing: + star tracker": "sensing: + gyro",
        "sensing: + MEKF": "sensing: + star tracker",
    }
    table = harness.table(
        f"avionics pieces, ns per call (min of {args.batches} batches)",
        ("piece", "ns / call", "added", "added / plant step"),
    )
    for name, value in ns.items():
        added = value - ns[against[name]] if name in against else None
        table.add_row(name, f"{value:.0f}", "" if added is None else f"{added:+.0f}",
                      "" if added is None else f"{added / step:+.1%}")  # fmt: skip
    harness.console().print(table)
    return ns


if __name__ == "__main__":
    main()

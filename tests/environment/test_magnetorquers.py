"""Magnetorquers: the cross-product law, the rods' limit and quantum, and a dumping run."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.environment.magnetorquers import dumping_dipole, magnetorquer_dipole

SEED = 7031


def test_the_law_takes_the_momentum_across_the_field_out() -> None:
    """tau = m x B with m = k (h x B)/|B|^2 is -k h_perp: exactly the momentum across
    the field, none along it (1e-12 relative, round-off)."""
    rng = np.random.default_rng(SEED)
    print(f"seed {SEED}")
    for _ in range(20):
        B = rng.normal(size=3) * 3e-5
        h = rng.normal(size=3)
        k = 0.01
        m = np.array(dumping_dipole(tuple(B), tuple(h), k))
        b = B / np.linalg.norm(B)
        h_perp = h - b * (b @ h)
        assert np.cross(m, B) == pytest.approx(-k * h_perp, rel=1e-12, abs=1e-12 * k)
        assert abs(m @ B) < 1e-12 * np.linalg.norm(m) * np.linalg.norm(B)


def test_the_rods_limit_and_quantum() -> None:
    """Each axis clipped to the limit, then on the quantum's grid; 0 is continuous."""
    m = magnetorquer_dipole((12.0, -3.26, 0.04), 10.0, 0.5)
    assert m == (10.0, -3.5, 0.0)
    assert magnetorquer_dipole((12.0, -3.26, 0.04), 10.0, 0.0) == (10.0, -3.26, 0.04)
    assert magnetorquer_dipole((9.9, 0.0, 0.0), 10.0, 4.0)[0] == 8.0
    # 10 rounds to 12 on a 4 A m^2 grid: the drive stops at its last step inside 10
    assert magnetorquer_dipole((12.0, -30.0, 0.0), 10.0, 4.0) == (8.0, -8.0, 0.0)
    # a resolution coarser than the limit leaves nothing to command
    assert magnetorquer_dipole((12.0, -3.0, 1.0), 1.0, 2.0) == (0.0, 0.0, 0.0)


def _dumping_runs(monkeypatch, orbits: float = 3.0) -> tuple[dict, float]:
    """A satellite held inertially by four wheels (PD law) against a constant 2.8e-4 N m
    disturbance, in a 500 km sun-synchronous orbit, with and without magnetorquers
    (dipole field). Its panels' root translations are locked (their 50 Hz joints
    would need a 5 ms step): the 0.25-0.8 Hz modes at 50 ms, three orbits in seconds."""
    import tomllib

    import flexsat.simulate.stage_chain as stage_chain
    from flexsat.config import preset_path, validate_config
    from flexsat.dynamics.plant import Plant
    from flexsat.environment.gravity_gradient import MU_EARTH
    from flexsat.environment.loads import environment_data
    from flexsat.simulate.closedloop import run_slew
    from flexsat.simulate.scenario import SlewScenario
    from tests.environment.orbits import circular_ephemeris

    data = tomllib.loads(preset_path("nominal").read_text())
    for app in data["appendages"]:
        app["locked_dofs"] = ["eta_x", "eta_y", "eta_z"]
    plant = Plant.from_config(validate_config(data))
    period = 2.0 * np.pi * np.sqrt((6_378_137.0 + 500e3) ** 3 / MU_EARTH)
    duration = round(orbits * period / 10.0) * 10.0
    eph = circular_ephemeris(500e3, 97.4, duration + 20.0, 10.0)

    def environment(scenario, plant, layout=None):  # the ephemeris of a known orbit
        column = next(c.start for ch, c in layout.channels() if ch.name == "wheel_momentum_B")
        return environment_data(plant, scenario.environment, eph, "2026-01-01T00:00:00Z",
                                column)  # fmt: skip

    monkeypatch.setattr(stage_chain, "slew_environment", environment)
    runs = {}
    rods = {"dipole_max_a_m2": 20.0, "gain_1_s": 2e-3}
    for label, torquers in (("wheels only", None), ("magnetorquers", rods)):
        env = {"models": {"magnetic": {}}}
        if torquers:
            env["magnetorquers"] = torquers
        scenario = SlewScenario(
            duration_s=duration, dt_s=0.05, control_dt_s=0.5, record_dt_s=10.0,
            target_euler_deg=(0.0, 0.0, 0.0), controller={"kind": "pd"},
            actuator={"kind": "wheels", "motor_time_constant_s": 0.1, "t_max_nm": 0.1},
            disturbances={"environment_nm": (2e-4, -1e-4, 1.5e-4), "sloshing_ratio": 0.0},
            environment=env,
        )  # fmt: skip
        result = run_slew(plant, scenario)
        assert result.dataset.attrs["status"] == "ok"
        runs[label] = result.dataset
    return runs, period


def _per_orbit_peak(ds, period: float) -> list[float]:
    t = ds["time"].values
    h = np.linalg.norm(ds["wheel_momentum_B"].values, axis=1)
    return [float(h[(t >= k * period) & (t < (k + 1) * period)].max())
            for k in range(round(t[-1] / period))]  # fmt: skip


def test_dumping_keeps_the_wheel_momentum_bounded_over_three_orbits(monkeypatch) -> None:
    """Without magnetorquers the wheels store the disturbance's impulse, 1.6 N m s per
    orbit (2.8e-4 N m x 5677 s): the peak grows orbit after orbit. With them the peak
    of each orbit stays within 10 % of the first orbit's (the field's pattern repeats
    only roughly: the Earth turns under the orbit) and under a fifth of the undumped
    run's last peak. The cross-product law's gain (2e-3 1/s) dumps the momentum across
    the field in ~500 s; what it leaves is the part along the field."""
    runs, period = _dumping_runs(monkeypatch)
    free = _per_orbit_peak(runs["wheels only"], period)
    dumped = _per_orbit_peak(runs["magnetorquers"], period)
    print(f"peak |h_w| per orbit [N m s]: wheels only {free}, with magnetorquers {dumped}")
    assert free[2] > 2.5 * free[0]
    assert max(dumped) < 1.1 * dumped[0]
    assert max(dumped) < 0.2 * free[2]


def test_magnetorquers_without_wheels_are_refused_when_the_scenario_is_read() -> None:
    """The scenario itself refuses them (not only the run's set-up), so a campaign's
    check of its base scenario stops before any case flies."""
    from pydantic import ValidationError

    from flexsat.simulate.scenario import SlewScenario

    table = {
        "orbit": {"altitude_m": 500e3},
        "environment": {"models": {"magnetic": {}}, "magnetorquers": {}},
    }
    with pytest.raises(ValidationError, match="the \\[actuator\\] must be kind = 'wheels'"):
        SlewScenario.model_validate(table)
    wheels = {**table, "actuator": {"kind": "wheels"}}
    assert SlewScenario.model_validate(wheels).environment.magnetorquers is not None

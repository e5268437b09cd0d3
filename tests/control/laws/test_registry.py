"""A law written outside the package: a compiled quaternion PID with a 3-axis integral.

Defined, compiled and registered in this file with one line, as a user would in
their own file; it then flies the thesis slew in the compiled loop, from the
scenario table and from ``flexsat slew --controller``, and its diagnostics land
in the result with their units.
"""

from __future__ import annotations

import json
from importlib.metadata import EntryPoint
from typing import Literal, NamedTuple

import numpy as np
import pytest
from numba import njit
from pydantic import Field
from typer.testing import CliRunner

from flexsat.control import Channel, LawConfig, LawSpec, register_law
from flexsat.control.laws import LAW_SIGNATURE, LAWS, law_names
from flexsat.control.quaternion import quaternion_error
from flexsat.simulate import SlewScenario, design_inertia, run_slew


class PIDGains(NamedTuple):
    limit: float  # RF * T_max [N m]
    kp: float  # [1/s^2]
    ki: float  # [1/s^3]
    kd: float  # [1/s]
    window: float  # |q_v,e| below which the error is integrated [-]


G = PIDGains(*range(len(PIDGains._fields)))


class PIDConfig(LawConfig):
    """tau = w x Jw - J (kp q_v,e + ki int q_v,e dt + kd w), clipped to RF * T_max."""

    kind: Literal["qpid"] = "qpid"
    natural_frequency_rad_s: float = Field(0.3, gt=0.0)
    damping_ratio: float = Field(0.9, gt=0.0)
    ki: float = Field(0.02, ge=0.0, description="integral gain [1/s^3]")
    window_deg: float = Field(2.0, gt=0.0, description="integrate below this error [deg]")

    def gains(self, actuator) -> np.ndarray:
        wn = self.natural_frequency_rad_s
        return np.array(PIDGains(
            actuator.reduction_factor * actuator.t_max_nm, 2.0 * wn**2, self.ki,
            2.0 * self.damping_ratio * wn, np.sin(np.radians(self.window_deg) / 2.0),
        ))  # fmt: skip


@njit(LAW_SIGNATURE, cache=True)
def pid_step(q_d, omega_d, omega_dot_d, q, omega_B, J, gains, state, t, dt, tau_cmd, diag):
    e = quaternion_error(q_d, q)
    if e[1] ** 2 + e[2] ** 2 + e[3] ** 2 < gains[G.window] ** 2:  # no wind-up while slewing
        for a in range(3):
            state[a] += e[1 + a] * dt
    # u = kp q_v,e + ki int q_v,e dt + kd w, kept in tau_cmd (nothing allocated)
    for a in range(3):
        tau_cmd[a] = gains[G.kp] * e[1 + a] + gains[G.ki] * state[a] + gains[G.kd] * omega_B[a]
    w = omega_B
    Jw = (J[0, 0] * w[0] + J[0, 1] * w[1] + J[0, 2] * w[2],
          J[1, 0] * w[0] + J[1, 1] * w[1] + J[1, 2] * w[2],
          J[2, 0] * w[0] + J[2, 1] * w[1] + J[2, 2] * w[2])  # fmt: skip
    gyro = (w[1] * Jw[2] - w[2] * Jw[1], w[2] * Jw[0] - w[0] * Jw[2], w[0] * Jw[1] - w[1] * Jw[0])
    Ju = (J[0, 0] * tau_cmd[0] + J[0, 1] * tau_cmd[1] + J[0, 2] * tau_cmd[2],
          J[1, 0] * tau_cmd[0] + J[1, 1] * tau_cmd[1] + J[1, 2] * tau_cmd[2],
          J[2, 0] * tau_cmd[0] + J[2, 1] * tau_cmd[1] + J[2, 2] * tau_cmd[2])  # fmt: skip
    for a in range(3):
        tau_cmd[a] = min(gains[G.limit], max(-gains[G.limit], gyro[a] - Ju[a]))
        diag[a] = state[a]
    return 0


BUILT_IN = law_names()  # before this file's law is registered

QPID = LawSpec(
    name="qpid", label="QPID", config=PIDConfig, step=pid_step, state_size=3,
    diagnostics=(Channel("pid_integral", "s", "integral of q_v,e", per_axis=True),),
    description="quaternion PID (a user's law)",
)  # fmt: skip


@pytest.fixture(scope="module")
def qpid():
    register_law(QPID)  # the one line a user writes
    yield QPID
    LAWS.unregister(QPID.name)


@pytest.fixture(scope="module")
def pid_slew(qpid, nominal_plant):
    scenario = SlewScenario.model_validate({"controller": {"kind": "qpid"}})
    return scenario, run_slew(nominal_plant, scenario).dataset


def test_user_law_flies_the_thesis_slew_in_the_compiled_loop(pid_slew):
    scenario, ds = pid_slew
    assert ds.attrs["status"] == "ok" and ds.attrs["controller"] == "qpid"
    # The integral removes the standing error the constant disturbances leave the
    # PD (~0.08 deg): well inside R1 (0.05 deg) at the end of the 120 s slew.
    assert ds["pointing_error_deg"].values[-1] < 5e-3
    assert np.all(np.abs(ds["tau_applied"].values) <= scenario.actuator.t_max_nm)


def test_user_law_diagnostics_are_in_the_result_with_units(pid_slew):
    scenario, ds = pid_slew
    integral = ds["pid_integral"]
    assert integral.dims == ("time", "axis") and integral.attrs["units"] == "s"
    # At rest on the target the integral term alone holds off the constant torques:
    # G_act (-J ki I) + environment = 0, so I = J^-1 env / (G_act ki) per axis. The
    # sloshing term is proportional to the small residual command and the integral
    # is still settling (slowest closed-loop pole ~0.1 1/s): 5 % of its value.
    J = design_inertia()
    env = np.array(scenario.disturbances.environment_nm)
    expected = np.linalg.solve(J, env) / (0.95 * scenario.controller.ki)
    np.testing.assert_allclose(integral.values[-1], expected, rtol=0.05)
    # no sliding surface: the plots find nothing to draw
    assert "surface_lambda_min_rad_s" not in ds.attrs


def test_cli_picks_up_the_registered_law(qpid, tmp_path):
    from flexsat.cli.main import app

    short = tmp_path / "short.toml"  # a 2 s run holds its observation window
    short.write_text("[requirements]\nsettling_deadline_s = 1.0\n")
    result = CliRunner().invoke(app, ["slew", "--scenario", str(short), "--controller", "qpid",
                                      "--duration", "2", "--json"])  # fmt: skip
    assert result.exit_code == 0, result.output
    metrics = json.loads(result.stdout.strip().splitlines()[-1])
    assert metrics["controller"] == "qpid"
    np.testing.assert_allclose(metrics["design_inertia_kg_m2"], design_inertia())
    assert "qpid" in law_names()


def test_unknown_law_lists_the_registered_ones(qpid):
    from flexsat.cli.main import app
    from flexsat.errors import ConfigError

    # The flexsat command turns this error into one line and exit code 2 (tests/cli).
    result = CliRunner().invoke(app, ["slew", "--controller", "qpdi", "--duration", "1"])
    assert isinstance(result.exception, ConfigError)
    # every kind a table may name, the laws that need a file (statespace, hybrid) included
    allowed = f"{', '.join(BUILT_IN)}, statespace, hybrid, qpid"
    assert f"must be one of {allowed} (got 'qpdi')" in str(result.exception)


def test_installed_laws_are_found_through_the_entry_point_group(qpid, tmp_path, monkeypatch):
    import flexsat.control.registry as registry

    # An installed package's module whose import registers its law, named by an
    # entry point of the group flexsat.laws (here: this file's law).
    (tmp_path / "installed_flexsat_law.py").write_text(
        f"from flexsat.control import register_law\nfrom {__name__} import QPID\n"
        "register_law(QPID)\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))

    def entry_points(group):
        found = [EntryPoint("qpid", "installed_flexsat_law", group)]
        return found if group == "flexsat.laws" else []

    LAWS.unregister(QPID.name)
    monkeypatch.setattr(registry, "entry_points", entry_points)
    monkeypatch.setattr(LAWS, "_discovered", False)  # as in a fresh process
    assert law_names() == (*BUILT_IN, "qpid")

"""Effective inertia, the rigid reference model and the loop margins of the laws."""

import numpy as np
import pytest

from flexsat.control.laws.asmc import ASMCConfig
from flexsat.control.laws.smc import SMCConfig
from flexsat.control.laws.stsmc import STSMCConfig
from flexsat.errors import ConfigError
from flexsat.linear.frequency import (
    effective_inertia,
    law_gains,
    loop_margins,
    pd_gains,
    pd_loop,
    rigid_model,
)


def test_effective_inertia_of_the_flapping_panels(plant):
    f, J_eff, J_res = effective_inertia(plant)
    # Hub-fixed appendage modes are the tuned cantilever targets (thesis table 3.1):
    # flapping 0.25 Hz, in-plane 0.5 Hz, torsion 0.8 Hz, one per panel (the tuning
    # uses diag M only, so the in-plane pair sits 4e-5 below its target).
    np.testing.assert_allclose(f[:6], [0.25, 0.25, 0.5, 0.5, 0.8, 0.8], rtol=1e-4)
    # Flapping about X_M of a uniform panel (m = 6.75 kg, L = 4.5 m, root at d = 0.8 m
    # from the hub axis): J_eff = (m L^2/12 + m (L/2)(d + L/2))^2 / (m L^2/3)
    # = 57.71^2 / 45.56 = 73.10 kg m^2 per panel; the root translations couple at
    # (0.25/50)^2 ~ 3e-5 relative and the 2 cm thickness at 2e-5: 1e-3.
    m, L, d = 6.75, 4.5, 0.8
    hand = (m * L**2 / 12 + m * L / 2 * (d + L / 2)) ** 2 / (m * L**2 / 3)
    np.testing.assert_allclose(J_eff[:2, 0], hand, rtol=1e-3)
    # With full 6-DOF joints the residual is the bare hub (eqs. 2.3-2.4: 41.625,
    # 41.625, 27.0 kg m^2), and everything adds up to the locked inertia (round-off).
    np.testing.assert_allclose(J_res, np.diag(plant.hub_J), rtol=1e-9)
    np.testing.assert_allclose(
        J_eff.sum(axis=0) + J_res, np.diag(plant.locked_inertia(plant.zeros())), rtol=1e-12
    )


def test_rigid_model_is_the_flexible_one_at_low_frequency(plant, rest_model):
    rigid = rigid_model(plant)
    rate = ["omega_x", "omega_y", "omega_z"]
    f = 1e-3  # [Hz], 250 times below the first flexible mode: (f / f_1)^2 ~ 2e-5
    G = rest_model.select(outputs=rate).frequency_response(f)[0]
    Gr = rigid.select(outputs=rate).frequency_response(f)[0]
    np.testing.assert_allclose(G, Gr, rtol=1e-4, atol=1e-4 * np.abs(Gr).max())


@pytest.fixture(scope="module")
def loops(plant, rest_model):
    K = pd_gains(plant)
    return {axis: pd_loop(rest_model, K, axis) for axis in "xyz"}


# python-control forms the loop's polynomials (degree 36) internally and warns of
# overflow in their evaluation; its margins are still right (checked here).
@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_phase_margin_agrees_with_python_control(loops):
    from scipy.signal import ss2tf

    import control

    for loop in loops.values():
        ours = loop_margins(loop)
        # python-control's polynomial pass on scipy's transfer function, with or without
        # slycot (whose tb04ad conversion of this stiff loop finds spurious crossings).
        ss = loop.to_statespace()
        num, den = ss2tf(ss.A, ss.B, ss.C, ss.D)
        gm, pm, _, _, wpm, _ = control.stability_margins(control.tf(num[0], den))
        # Same loop, two root finders on the exact response: 1e-8 relative.
        assert ours.phase_margin_deg == pytest.approx(pm, rel=1e-8)
        assert 2 * np.pi * ours.gain_crossover_hz == pytest.approx(wpm, rel=1e-8)
        assert np.isinf(ours.gain_margin) and np.isinf(gm)


def test_pd_loop_rigid_crossover_and_flexible_delay_limit(loops):
    # Rigid design: L = (wn^2 + 2 zeta wn s) / s^2 with wn = 0.3 rad/s, zeta = 0.9:
    # |L| = 1 at w^4 = wn^4 + 4 zeta^2 wn^2 w^2, i.e. w = 0.5555 rad/s (0.0884 Hz);
    # phase margin atan(2 zeta w / wn) = 73.3 deg. The panels move the crossover by
    # up to 8 % (about X, where 77 % of the inertia sits in the 0.26 Hz flapping
    # modes): 10 %.
    wn, zeta = 0.3, 0.9
    w2 = 2 * zeta**2 * wn**2 + np.sqrt(4 * zeta**4 * wn**4 + wn**4)
    w = np.sqrt(w2)
    pm = np.degrees(np.arctan(2 * zeta * w / wn))
    for loop in loops.values():
        margins = loop_margins(loop)
        assert margins.gain_crossover_hz == pytest.approx(w / (2 * np.pi), rel=0.10)
        assert margins.phase_margin_deg == pytest.approx(pm, abs=1.5)
    # About X and Z a flexible peak rises above 0 dB: the delay margin is set there,
    # well below the rigid value pm / w_c = 2.3 s.
    for axis in "xz":
        m = loops[axis]
        margins = loop_margins(m)
        assert len(margins.crossovers_hz) == 3
        assert margins.delay_crossover_hz > 0.4
        assert margins.delay_margin_s < 0.5
    rigid_delay = np.radians(pm) / w
    assert loop_margins(loops["y"]).delay_margin_s == pytest.approx(rigid_delay, rel=0.05)


@pytest.mark.parametrize(
    ("law", "lam", "jk", "shift"),
    # defaults (thesis section 5.1); the allowed crossover shift by the flexible modes
    # (see below): SMC crosses at 0.40 Hz, half the 0.82 Hz coupled torsion mode;
    # the ASMC (Lambda = 5) at 0.66 Hz, close under it, and is pulled 11 % down.
    [(SMCConfig(), 1.0, 0.8925, 0.05), (ASMCConfig(), 5.0, 0.8925, 0.15)],
)
def test_sliding_mode_loops_inside_the_boundary_layer(plant, rest_model, law, lam, jk, shift):
    K = law_gains(plant, law)
    phi = 0.01  # [rad/s] boundary layer
    J = plant.locked_inertia(plant.zeros())  # = J_tot at rest
    # tau = -Lambda J w/2 - (JK/Phi)(w + Lambda theta/2): rigid loop about Y, the
    # axis with the least flexible coupling (J_eff 1.3 of 44 kg m^2):
    # L = (k_t + k_w s) / (J_yy s^2) with k_t = JK Lambda / (2 Phi), k_w = Lambda J_yy/2 + JK/Phi.
    k_t, k_w = jk * lam / (2 * phi), lam * J[1, 1] / 2 + jk / phi
    np.testing.assert_allclose(K[1, [1, 4]], [k_t, k_w], rtol=1e-12)
    # |L| = 1 at w^4 J^2 = k_t^2 + k_w^2 w^2
    a = J[1, 1] ** 2
    w2 = (k_w**2 + np.sqrt(k_w**4 + 4 * a * k_t**2)) / (2 * a)
    margins = loop_margins(pd_loop(rest_model, K, "y"))
    # The torsion modes (0.8 Hz) sit above the crossover and pull it down by `shift`.
    assert margins.gain_crossover_hz == pytest.approx(np.sqrt(w2) / (2 * np.pi), rel=shift)


def test_a_law_without_a_linear_form_is_refused_naming_the_ones_with_one(plant):
    # The super-twisting term |s|^1/2 sgn(s) has no derivative at s = 0.
    with pytest.raises(ConfigError, match=r"no linear form about rest.*asmc, smc, pd"):
        law_gains(plant, STSMCConfig())


def test_loop_of_an_unknown_axis_is_refused(plant, rest_model):
    with pytest.raises(ConfigError, match="axis: unknown axis 'w'"):
        pd_loop(rest_model, pd_gains(plant), "w")


def _pd_closed_loop_with_delay(plant, delay_s, duration_s=30.0, dt=2e-3):
    """The nonlinear closed loop with the PD law and the computational-delay stage.

    RK4 at 2 ms (the 100 Hz joint modes need dt < 4.4 ms for RK4 stability), the
    law every step, its command delayed by round(delay_s / dt) control periods
    (``actuator_stages = [{kind = "delay"}]``), applied without gain error,
    disturbance or saturation (T_max far away: the linear loop has none). Starts at
    rest, holding the identity, with a 1e-3 rad/s yaw rate.
    Returns tau_z, one value per step.
    """
    from flexsat.simulate import SlewScenario, run_slew

    scenario = SlewScenario.model_validate({
        "duration_s": duration_s, "dt_s": dt, "control_dt_s": dt, "record_dt_s": dt,
        "target_euler_deg": [0.0, 0.0, 0.0], "controller": {"kind": "pd"},
        "initial": {"rate_deg_s": [0.0, 0.0, float(np.degrees(1e-3))]},
        "actuator_stages": [{"kind": "delay", "periods": round(delay_s / dt)}],
        "actuator": {"kind": "static", "gain": [1.0, 1.0, 1.0], "t_max_nm": 1e4},
        "disturbances": {"environment_nm": [0.0, 0.0, 0.0], "sloshing_ratio": 0.0},
    })  # fmt: skip
    ds = run_slew(plant, scenario).dataset
    return ds["tau_applied"].values[:-1, 2]


def test_delay_margin_matches_the_nonlinear_closed_loop(plant, loops):
    margins = loop_margins(loops["z"])  # the smallest of the three axes
    dt = 2e-3  # [s]
    below = np.diff(_pd_closed_loop_with_delay(plant, 0.9 * margins.delay_margin_s, dt=dt))
    above = np.diff(_pd_closed_loop_with_delay(plant, 1.1 * margins.delay_margin_s, dt=dt))
    # The step-to-step change of tau_z isolates the fast (flexible) part of the loop.
    # Acceptance: stable 10 % below the predicted margin, unstable 10 % above it.
    third = below.size // 3
    assert np.abs(below[-third:]).max() < 0.5 * np.abs(below[third : 2 * third]).max()
    assert np.abs(above[-third:]).max() > 3 * np.abs(above[third : 2 * third]).max()
    # ... and the growing oscillation is at the limiting crossover frequency (the
    # closed-loop pole crosses the imaginary axis there): FFT resolution 1/10 s.
    tail = above[-third:] * np.hanning(third)
    freqs = np.fft.rfftfreq(8 * third, dt)
    f_peak = freqs[np.argmax(np.abs(np.fft.rfft(tail, 8 * third)))]
    assert f_peak == pytest.approx(margins.delay_crossover_hz, abs=1.0 / (third * dt))


def _control_loop(npz, K: np.ndarray, a: int):
    """The loop gain of axis a built by python-control alone from an exported model."""
    import control

    names = [str(n) for n in npz["output_names"]]
    rows = [names.index(n) for n in ("phi", "theta", "psi", "omega_x", "omega_y", "omega_z")]
    plant = control.ss(npz["A"], npz["B"][:, :3], npz["C"][rows], npz["D"][rows][:, :3])
    others = K.copy()
    others[a] = 0.0  # the other two axes' loops closed, this one open
    closed = control.feedback(plant, control.ss([], [], [], others))  # u = r - K_o y
    return control.series(closed[:, a], control.ss([], [], [], K[[a]]))


# python-control's margins solve degree-72 polynomials (see above).
@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_every_crossover_and_flexible_peak_against_python_control(plant, rest_model, tmp_path):
    import control
    from flexsat.study.linear import write_margins

    rest_model.save_npz(tmp_path / "model.npz")
    npz = np.load(tmp_path / "model.npz")
    K = pd_gains(plant)
    axes = write_margins(plant)["axes"]  # what `flexsat margins --json` prints
    phase_stabilized = {}
    for a, axis in enumerate("xyz"):
        loop = _control_loop(npz, K, a)
        _, pm, _, _, wc, _ = control.stability_margins(loop, returnall=True)
        ours = axes[axis]["crossovers"]
        # Every gain crossover, and its phase margin: two root finders on the same
        # exact response (python-control's polynomial |L|^2 = 1, flexsat's Brent on
        # the grid's brackets), 1e-8 relative as for the smallest margin above.
        np.testing.assert_allclose([c["frequency_hz"] for c in ours], np.sort(wc) / (2 * np.pi),
                                   rtol=1e-8)  # fmt: skip
        np.testing.assert_allclose([c["phase_margin_deg"] for c in ours], pm[np.argsort(wc)],
                                   rtol=1e-8, atol=1e-8)  # fmt: skip
        # The delay margin is the smallest (PM mod 360 deg) / (360 deg f_c), at its crossover.
        delays = np.remainder(pm, 360.0) / np.degrees(wc)
        k = int(np.argmin(delays))
        assert axes[axis]["delay_margin_s"] == pytest.approx(delays[k], rel=1e-8)
        assert axes[axis]["delay_crossover_hz"] == pytest.approx(wc[k] / (2 * np.pi), rel=1e-8)
        # Peaks: |L| of the python-control loop around each of its lightly damped poles
        # in the band (above 1e-4 Hz), on 2001 points over +-(20 zeta + 1e-3) (at most
        # +-50 %) of the pole's frequency, then 2001 points over the two spacings beside the best:
        # final spacing <= 2e-8 relative, so the grid's maximum is below the true peak
        # by (spacing / 2 zeta)^2 / 2 < 1e-11 relative for zeta >= 0.005 (the panels'):
        # the peaks agree to 1e-5 dB and 1e-6 relative in frequency.
        lam = np.linalg.eigvals(loop.A)
        light = (lam.imag > 0) & (-lam.real < 0.3 * np.abs(lam)) & (np.abs(lam) > 2e-4 * np.pi)
        reference = []
        for pole in lam[light]:
            zeta, w = -pole.real / abs(pole), abs(pole)
            half = min(20 * zeta + 1e-3, 0.5)
            omega = w * np.linspace(1 - half, 1 + half, 2001)
            mag = np.abs(loop.frequency_response(omega).magnitude).ravel()
            k = int(np.argmax(mag))
            if not 0 < k < mag.size - 1:
                continue  # no peak inside the window: the pole is cancelled in this loop
            omega = np.linspace(omega[k - 1], omega[k + 1], 2001)
            mag = np.abs(loop.frequency_response(omega).magnitude).ravel()
            k = int(np.argmax(mag))
            f_k, db = omega[k] / (2 * np.pi), 20 * np.log10(mag[k])
            if all(abs(f_k / f - 1) > 1e-5 for f, _ in reference):  # a pair shows one peak
                reference.append((f_k, db))
        reference = np.array(reference)
        for peak in axes[axis]["flexible_peaks"]:
            j = int(np.argmin(np.abs(reference[:, 0] / peak["peak_hz"] - 1)))
            assert peak["peak_hz"] == pytest.approx(reference[j, 0], rel=1e-6)
            assert peak["peak_gain_db"] == pytest.approx(reference[j, 1], abs=1e-5)
            # Definition (docs/linear.md, "Loop gains and margins"): below 0 dB, gain.
            assert peak["stabilized"] == ("phase" if reference[j, 1] >= 0.0 else "gain")
        # No mode above 0 dB is missed: each adds two crossovers, so it must be listed.
        above = reference[reference[:, 1] >= 0.0]
        listed = [p for p in axes[axis]["flexible_peaks"] if p["stabilized"] == "phase"]
        assert len(listed) == len(above) and len(ours) == 1 + 2 * len(above)
        phase_stabilized[axis] = [(p["peak_hz"], p["peak_gain_db"]) for p in listed]
    # The x loop: one phase-stabilized mode, 0.521 Hz at +28.5 dB, between the 0.415
    # and 0.709 Hz crossovers; y: none; z: the 1.231 Hz mode at +23.1 dB.
    assert [round(f, 3) for f, _ in phase_stabilized["x"]] == [0.521]
    assert phase_stabilized["x"][0][1] == pytest.approx(28.46, abs=0.01)
    assert phase_stabilized["y"] == []
    assert [round(f, 3) for f, _ in phase_stabilized["z"]] == [1.231]

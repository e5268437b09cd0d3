"""The linear model against the modal analysis and the nonlinear simulation."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.signal import find_peaks

from flexsat.analysis.modal import modal_analysis
from flexsat.errors import ConfigError
from flexsat.linear import linearize
from flexsat.simulate import run_openloop
from flexsat.simulate.scenario import (
    AppendageInitialState,
    InitialState,
    OpenLoopScenario,
    pulse,
)


def _flexible_frequencies_hz(model) -> np.ndarray:
    lam = model.poles()
    return np.sort(np.abs(lam[lam.imag > 1e-6]))[:] / (2 * np.pi)


def test_richardson_reproduces_the_analytic_rest_jacobian(plant, rest_model):
    fd = linearize(plant, jacobian="richardson")
    assert rest_model.jacobian == "analytic" and fd.jacobian == "richardson"
    # O(h^4) truncation ~1e-16 and round-off ~eps/h ~1e-12 of the largest entry
    # (the 50 Hz joint stiffness, ~4e5 s^-2); 1e-9 leaves margin for both.
    assert np.max(np.abs(fd.A - rest_model.A)) <= 1e-9 * np.max(np.abs(rest_model.A))
    assert np.max(np.abs(fd.B - rest_model.B)) <= 1e-9 * np.max(np.abs(rest_model.B))


def test_undamped_eigenvalues_are_the_modal_frequencies(plant):
    undamped = plant.with_joints(plant.stiffness, np.zeros_like(plant.damping))
    model = linearize(undamped)
    lam = model.poles()
    assert np.max(np.abs(lam.real)) <= 1e-9 * np.max(np.abs(lam))  # purely imaginary
    modal = modal_analysis(undamped).frequencies_hz[6:]  # thesis table 3.3 (coupled)
    linear = _flexible_frequencies_hz(model)
    # Same M(0), K; eig of the 36 x 36 first-order form vs eigh of the pencil: both
    # backward stable; measured 1.2e-11 relative; 1e-9 is the acceptance figure.
    np.testing.assert_allclose(linear, modal, rtol=1e-9)


def test_damped_poles_match_modal_damping_to_first_order(plant, rest_model):
    modal = modal_analysis(plant)
    omega = 2 * np.pi * modal.frequencies_hz[6:]
    phi = modal.shapes[:, 6:]
    zeta = np.diag(phi.T @ plant.damping_matrix() @ phi) / (2 * omega)  # modal damping
    lam = rest_model.poles()
    lam = lam[lam.imag > 1e-6]
    lam = lam[np.argsort(np.abs(lam))]
    zeta_max = zeta.max()
    # |lambda_k| = omega_k and -Re/|lambda| = zeta_k up to the second order in zeta
    # (non-proportional damping couples modes at O(zeta^2)); the modal zeta reach
    # 0.012 here, a bound of 10 zeta^2 = 1.5e-3. Measured: 8e-9 on |lambda| and 1e-10
    # on zeta (the joint dampers are tuned per mode, nearly proportional).
    np.testing.assert_allclose(np.abs(lam), omega, rtol=10 * zeta_max**2)
    np.testing.assert_allclose(-lam.real / np.abs(lam), zeta, rtol=0.0, atol=10 * zeta_max**2)


def _steady_response(plant, model, f_hz: float, torque_z: float = 1e-3) -> complex:
    """Nonlinear omega_z / tau_z at f_hz from a run started on the periodic orbit."""
    n = plant.n_dof
    w = 2 * np.pi * f_hz
    U = np.array([0.0, 0.0, torque_z])
    X = np.linalg.solve(1j * w * np.eye(2 * n) - model.A, model.B @ U)  # x = Im(X e^iwt)
    x0 = X.imag  # first-order plant state at t = 0 (S(0) = I at rest)

    def rhs(t, y):
        q, qd = y[:n], y[n:]
        Q = plant.generalized_forces(q, U * np.sin(w * t))
        return np.concatenate([qd, plant.accelerations(q, qd, Q)])

    periods = 2
    t = np.linspace(0.0, periods / f_hz, 400 * periods, endpoint=False)
    sol = solve_ivp(rhs, (0.0, t[-1]), x0, method="DOP853", t_eval=t, rtol=1e-10, atol=1e-13)
    assert sol.success
    omega_z = np.array([plant_rate(plant, sol.y[:n, k], sol.y[n:, k])[2] for k in range(t.size)])
    # Least-squares fit omega_z = a sin + b cos over whole periods: Im(G U e^iwt).
    basis = np.column_stack([np.sin(w * t), np.cos(w * t)])
    a, b = np.linalg.lstsq(basis, omega_z, rcond=None)[0]
    return (a + 1j * b) / torque_z


def plant_rate(plant, q, qd):
    phi, theta = q[3], q[4]
    S = np.array(
        [
            [1, 0, -np.sin(theta)],
            [0, np.cos(phi), np.cos(theta) * np.sin(phi)],
            [0, -np.sin(phi), np.cos(theta) * np.cos(phi)],
        ]
    )
    return S @ qd[3:6]


@pytest.mark.parametrize("f_hz", [0.05, 0.15, 0.4, 1.0, 2.0, 5.0])
def test_torque_to_rate_matches_the_nonlinear_steady_state(plant, rest_model, f_hz):
    G = rest_model.select(outputs=["omega_z"], inputs=["tau_z"]).frequency_response(f_hz)[0, 0, 0]
    G_nl = _steady_response(plant, rest_model, f_hz)
    # Attitude amplitude <= 3e-4 rad: the nonlinear terms are O(amplitude) relative,
    # ~1e-4, and DOP853 at rtol 1e-10 adds nothing visible; the acceptance is 1 %.
    assert abs(G_nl - G) <= 0.01 * abs(G)


def test_spin_shifts_the_frequencies_as_a_time_domain_run_shows(plant, rest_model):
    W = 1.0  # [rad/s] spin about body X, the major axis of the locked inertia (stable)
    spin = linearize(plant, about=[W, 0.0, 0.0])
    assert np.linalg.norm(spin.u0) < 1e-12  # X is a principal axis: no holding torque
    duration, dt_rec = 400.0, 0.02  # [s]; resolution 1/duration = 2.5 mHz
    scenario = OpenLoopScenario(
        duration_s=duration,
        record_dt_s=dt_rec,
        torque=[],
        initial=InitialState(
            rate_deg_s=(np.degrees(W), 0.0, 0.0),
            appendages=[AppendageInitialState(name="panel_1", rho_deg=(0.05, 0.05, 0.0))],
        ),
    )
    rho = run_openloop(plant, scenario).dataset["rho"].sel(appendage="panel_1")
    resolution = 1.0 / duration
    f_spin = _flexible_frequencies_hz(spin)
    f_rest = _flexible_frequencies_hz(rest_model)
    peaks = []
    for axis in ("x", "y", "z"):
        signal = rho.sel(axis=axis).values
        signal = (signal - signal.mean()) * np.hanning(signal.size)
        spectrum = np.abs(np.fft.rfft(signal, 8 * signal.size))  # zero-padded x 8
        freqs = np.fft.rfftfreq(8 * signal.size, dt_rec)
        k, _ = find_peaks(spectrum, height=0.05 * spectrum.max())
        peaks += [f for f in freqs[k] if 0.02 < f < 2.0]
    assert len(peaks) >= 4
    for f in peaks:  # every peak of the run is a mode of the spin model
        assert np.min(np.abs(f_spin - f)) <= resolution
    # ... and the shifts are visible: the flapping peak is many resolutions away from
    # its rest frequency, and the nutation peak (~W/(2 pi) x inertia ratio) has no
    # counterpart at rest at all.
    flap = min(peaks, key=lambda f: abs(f - 0.27))
    assert np.min(np.abs(f_rest - flap)) > 4 * resolution
    assert min(peaks) < 0.1 and np.min(np.abs(f_rest - min(peaks))) > 0.1


def test_spin_about_the_intermediate_axis_is_unstable(plant):
    # Locked inertia: J_xx 190 > J_zz 178 > J_yy 44 kg m^2; a spin about Z (the
    # intermediate axis) is unstable, about X it is not (Euler's rigid-body result).
    assert linearize(plant, about=[0.0, 0.0, 0.5]).poles().real.max() > 0.1
    assert linearize(plant, about=[0.5, 0.0, 0.0]).poles().real.max() < 1e-9


def test_the_whole_model_converts_to_python_control(rest_model):
    # Tip outputs and joint states are named "panel_1.tip_x"...: python-control takes
    # the states as named and the outputs with "_" for ".".
    sys = rest_model.to_statespace()
    assert "panel_1_tip_x" in sys.output_labels and "panel_1.eta_x" in sys.state_labels
    assert sys.noutputs == len(rest_model.output_names)
    assert np.array_equal(sys.C, rest_model.C)


def test_statespace_round_trips_through_python_control(plant, rest_model):
    import control

    sub = rest_model.select(outputs=["omega_x", "phi"], inputs=["tau_x"])
    sys = sub.to_statespace()
    assert list(sys.output_labels) == ["omega_x", "phi"]
    f = np.array([0.05, 0.3, 1.0, 4.0])
    mag, phase, _ = control.frequency_response(sys[0, 0], 2 * np.pi * f)
    G = sub.frequency_response(f)[:, 0, 0]
    np.testing.assert_allclose(mag, np.abs(G), rtol=1e-10)  # same linear algebra
    np.testing.assert_allclose(np.unwrap(phase), np.unwrap(np.angle(G)), atol=1e-8)
    # forced_response of the linear model = the nonlinear RK4 run of a small pulse.
    torque = 1e-3  # [N m] for 1 s about X: attitude stays below 1e-4 rad
    run = run_openloop(
        plant,
        OpenLoopScenario(
            duration_s=10.0, record_dt_s=1e-3, torque=[pulse(0.0, 1.0, (torque, 0.0, 0.0))]
        ),
    ).dataset
    t = run["time"].values
    u = np.where(t < 1.0, torque, 0.0)
    u[np.searchsorted(t, 1.0)] = torque  # the run holds the torque up to the step at 1 s
    linear = control.forced_response(sys[0, 0], t, u).outputs
    omega_x = run["omega"].sel(axis="x").values
    # Nonlinear terms O(1e-4) relative, RK4 at 1 ms ~1e-6 on these < 2 Hz modes, the
    # interpolated input near the switching instant ~1e-3: 1 % of the peak.
    assert np.max(np.abs(linear - omega_x)) <= 0.01 * np.max(np.abs(omega_x))


def test_mat_and_npz_files_hold_the_documented_variables(rest_model, tmp_path):
    from scipy.io import loadmat

    from flexsat.linear import MAT_VARIABLES

    mat = loadmat(rest_model.save_mat(tmp_path / "model.mat"))
    for name in MAT_VARIABLES:
        assert name in mat
    np.testing.assert_array_equal(mat["A"], rest_model.A)
    names = [str(c[0]) for c in mat["output_names"].ravel()]
    assert names == list(rest_model.output_names)
    npz = np.load(rest_model.save_npz(tmp_path / "model.npz"))
    assert set(npz.files) == set(MAT_VARIABLES)
    np.testing.assert_array_equal(npz["C"], rest_model.C)
    assert list(npz["state_names"]) == list(rest_model.state_names)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda p, m: m.select(outputs=["omega_w"]), "outputs: unknown name 'omega_w'"),
        (lambda p, m: m.select(inputs=["tau_q"]), "inputs: unknown name 'tau_q'"),
        (lambda p, m: linearize(p, outputs=["tips"]), "outputs: unknown output 'tips'"),
        (lambda p, m: linearize(p, about=[0.0, 0.0, 0.0]), "zero length"),
        (lambda p, m: linearize(p, about=[1.0, 2.0]), "three finite numbers"),
        (lambda p, m: linearize(p, about="spinning"), "expected 'rest'"),
        (lambda p, m: linearize(p, about=[0, 0, 0.1], jacobian="analytic"), "about rest only"),
    ],
)
def test_bad_requests_give_one_clear_message(plant, rest_model, call, message):
    with pytest.raises(ConfigError, match=message):
        call(plant, rest_model)

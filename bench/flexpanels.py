"""The hinged flexible-panel scenario of Basilisk's dynamics-engine comparison, both sides.

Basilisk's ``examples/dynamicsComparison/scenarioCompareFlexPanels.py`` (AVSLab) builds
one physical system three ways: ``nHingedRigidBodyStateEffector``,
``spinningBodyNDOFStateEffector`` and its MuJoCo back end. This module states that
system once, from the published description and numbers, and builds it for flexsat
(the ``chain`` appendage model) and for each Basilisk engine:

* hub: 600 kg, inertia diag(400, 380, 360) kg m^2 about its centre of mass, which is
  the body-frame origin; initial rate (0.010, -0.020, 0.015) rad/s, attitude identity;
* two arrays, each a serial chain of N rigid segments (total 60 kg, 3 m), root hinges
  at (+-0.8, 0, 0) m on the hub, every hinge about the parent frame's +y, every
  segment frame aligned with its parent at zero angle. Segment k's centre of mass is
  at -d along its own x (d = 3 m / 2N), the next hinge at -2d: both arrays extend
  towards -x, as that script builds them;
* segment inertia about its centre of mass, segment frame: diag(i_ax, i_bar, i_bar),
  i_bar = m l^2 / 12, i_ax = max(0.05 i_bar, 1e-4) kg m^2;
* every hinge: k = 600 N m/rad, c = 5 N m s/rad; the root hinges start at 8 deg, the
  others at 0, all at rest relative to their parent;
* RK4 with dt = min(0.01 s, T / 200), T = 2 pi sqrt((i_bar + m d^2) / k) the period of
  one segment on its hinge; no gravity, no external load.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

HUB_MASS_KG = 600.0
HUB_INERTIA_KG_M2 = (400.0, 380.0, 360.0)
ARRAY_MASS_KG = 60.0
ARRAY_LENGTH_M = 3.0
HINGE_K = 600.0  # [N m/rad]
HINGE_C = 5.0  # [N m s/rad]
ROOT_X_M = 0.8
ROOT_ANGLE_DEG = 8.0
OMEGA0_B = (0.010, -0.020, 0.015)  # [rad/s]
STEPS_PER_PERIOD = 200.0
SEGMENT_COUNTS = (1, 2, 4, 8, 16, 32)
WINDOW_S = 8.0  # the accuracy window of that script
TIMING_STEPS = 600  # its fixed step budget per trial
TIMING_TRIALS = 5  # its median over trials
TIMING_WARMUP_STEPS = 100  # its discarded warm-up


def segment(n: int) -> SimpleNamespace:
    """Mass [kg], half-length d [m] and centroidal inertia (3, 3) [kg m^2] of a segment."""
    mass = ARRAY_MASS_KG / n
    half = ARRAY_LENGTH_M / (2.0 * n)
    i_bar = mass * (2.0 * half) ** 2 / 12.0
    return SimpleNamespace(mass=mass, half=half,
                           inertia=np.diag([max(0.05 * i_bar, 1e-4), i_bar, i_bar]))  # fmt: skip


def time_step(n: int) -> float:
    """dt = min(0.01 s, T / 200) [s], T the period of one segment on its hinge, rounded
    to the nanosecond as Basilisk's integer-nanosecond task clock runs it."""
    s = segment(n)
    period = 2.0 * math.pi * math.sqrt((s.inertia[1, 1] + s.mass * s.half**2) / HINGE_K)
    return round(min(0.01, period / STEPS_PER_PERIOD) * 1e9) * 1e-9


# -- flexsat ---------------------------------------------------------------------------


def flexsat_config(n: int) -> dict:
    """The satellite as a flexsat config dict: hub + two listed chains on ``ry`` hinges."""
    s = segment(n)

    def array(name: str, sign: float) -> dict:
        segments = []
        for k in range(n):
            joint = {"dofs": ["ry"], "stiffness": {"ry": HINGE_K}, "damping": {"ry": HINGE_C}}
            if k == 0:
                joint["initial"] = {"ry": ROOT_ANGLE_DEG}
            segments.append({
                "mass_kg": s.mass, "inertia_kg_m2": s.inertia.tolist(),
                "com_m": [-s.half, 0.0, 0.0], "next_joint_m": [-2.0 * s.half, 0.0, 0.0],
                "joint": joint,
            })  # fmt: skip
        return {"name": name, "model": "chain", "mount_point_m": [sign * ROOT_X_M, 0.0, 0.0],
                "segment_list": segments}  # fmt: skip

    return {
        "name": f"basilisk-flexpanels-{n}",
        "hub": {"mass_kg": HUB_MASS_KG, "inertia_kg_m2": np.diag(HUB_INERTIA_KG_M2).tolist()},
        "appendages": [array("array_plus", 1.0), array("array_minus", -1.0)],
    }


def flexsat_scenario(n: int, duration_s: float = WINDOW_S, record_every: int = 1) -> dict:
    """The open-loop scenario dict: no torque, hub rate OMEGA0_B, RK4 at :func:`time_step`."""
    dt = time_step(n)
    return {
        "name": f"basilisk-flexpanels-{n}", "duration_s": duration_s, "dt_s": dt,
        "record_dt_s": record_every * dt, "torque": [],
        "initial": {"rate_deg_s": np.degrees(OMEGA0_B).tolist()},
    }  # fmt: skip


def hinge_angles(ds) -> np.ndarray:
    """Hinge angles of a flexsat result, shape (m, 2, n) [rad]: array +x, then -x."""
    q = ds["q"].values
    names = [str(d) for d in ds["dof"].values]
    out = [q[:, [j for j, d in enumerate(names) if d.startswith(f"{a}.")]]
           for a in ("array_plus", "array_minus")]  # fmt: skip
    return np.stack(out, axis=1)


# -- Basilisk ----------------------------------------------------------------------------


def import_basilisk() -> SimpleNamespace:
    """The Basilisk modules every Basilisk benchmark uses (ImportError when Basilisk is
    not installed); ``mujoco`` is None when the wheel does not ship the MuJoCo back end."""
    import importlib.metadata

    from Basilisk.simulation import (
        extForceTorque,
        nHingedRigidBodyStateEffector,
        spacecraft,
        spinningBodyNDOFStateEffector,
        svIntegrators,
    )
    from Basilisk.utilities import SimulationBaseClass, macros

    try:
        from Basilisk.simulation import mujoco
    except ImportError:
        mujoco = None
    return SimpleNamespace(
        nHinged=nHingedRigidBodyStateEffector, ndof=spinningBodyNDOFStateEffector,
        spinningBodyNDOFStateEffector=spinningBodyNDOFStateEffector, extForceTorque=extForceTorque,
        spacecraft=spacecraft, svIntegrators=svIntegrators, mujoco=mujoco,
        SimulationBaseClass=SimulationBaseClass, macros=macros,
        version=importlib.metadata.version("bsk"),
    )  # fmt: skip


def mrp_rotation(sigma: np.ndarray):
    """scipy Rotation of MRP histories sigma_BN, shape (m, 3): B relative to N."""
    from scipy.spatial.transform import Rotation

    s2 = np.sum(sigma**2, axis=1)
    return Rotation.from_quat(np.column_stack([2.0 * sigma / (1.0 + s2)[:, None],
                                               (1.0 - s2) / (1.0 + s2)]))  # fmt: skip


def _col(v) -> list[list[float]]:
    return [[float(x)] for x in v]


def _sim(bsk, dt):
    sim = bsk.SimulationBaseClass.SimBaseClass()
    sim.CreateNewProcess("dyn").addTask(sim.CreateNewTask("dynTask", bsk.macros.sec2nano(dt)))
    return sim


def _hub(bsk, sim):
    sc = bsk.spacecraft.Spacecraft()
    sc.ModelTag = "hub"
    sc.hub.mHub = HUB_MASS_KG
    sc.hub.IHubPntBc_B = np.diag(HUB_INERTIA_KG_M2).tolist()
    sc.hub.omega_BN_BInit = _col(OMEGA0_B)
    sim.AddModelToTask("dynTask", sc)
    integrator = bsk.svIntegrators.svIntegratorRK4(sc)
    sc.setIntegrator(integrator)
    return sc, integrator


def build_nhinged(bsk, n: int, dt: float, record: bool) -> SimpleNamespace:
    """``nHingedRigidBodyStateEffector``: each array one effector of N hinged panels."""
    sim = _sim(bsk, dt)
    sc, integrator = _hub(bsk, sim)
    s = segment(n)
    keep, hinge_recorders = [sc, integrator], []
    for sign in (1.0, -1.0):
        eff = bsk.nHinged.NHingedRigidBodyStateEffector()
        eff.ModelTag = f"chain{'P' if sign > 0 else 'M'}"
        eff.r_HB_B = _col((sign * ROOT_X_M, 0.0, 0.0))
        eff.dcm_HB = np.eye(3).tolist()
        for k in range(n):
            panel = bsk.nHinged.HingedPanel()
            panel.mass, panel.d, panel.k, panel.c = s.mass, s.half, HINGE_K, HINGE_C
            panel.IPntS_S = s.inertia.tolist()
            panel.thetaInit = math.radians(ROOT_ANGLE_DEG) if k == 0 else 0.0
            eff.addHingedPanel(panel)
            keep.append(panel)
        sc.addStateEffector(eff)
        sim.AddModelToTask("dynTask", eff)
        keep.append(eff)
    return _finish(bsk, sim, sc, dt, record, keep, hinge_recorders)


def build_ndof(bsk, n: int, dt: float, record: bool) -> SimpleNamespace:
    """``spinningBodyNDOFStateEffector``: each array one effector of N spinning bodies."""
    sim = _sim(bsk, dt)
    sc, integrator = _hub(bsk, sim)
    s = segment(n)
    keep, effectors = [sc, integrator], []
    for sign in (1.0, -1.0):
        eff = bsk.ndof.SpinningBodyNDOFStateEffector()
        eff.ModelTag = f"ndofChain{'P' if sign > 0 else 'M'}"
        for k in range(n):
            body = bsk.ndof.SpinningBody()
            body.setMass(s.mass)
            body.setISPntSc_S(s.inertia.tolist())
            body.setSHat_S(_col((0.0, 1.0, 0.0)))
            body.setDCM_S0P(np.eye(3).tolist())
            body.setR_SP_P(_col((sign * ROOT_X_M, 0.0, 0.0) if k == 0 else (-2 * s.half, 0, 0)))
            body.setR_ScS_S(_col((-s.half, 0.0, 0.0)))
            body.setK(HINGE_K)
            body.setC(HINGE_C)
            body.setThetaInit(math.radians(ROOT_ANGLE_DEG) if k == 0 else 0.0)
            eff.addSpinningBody(body)
            keep.append(body)
        sc.addStateEffector(eff)
        sim.AddModelToTask("dynTask", eff)
        keep.append(eff)
        effectors.append(eff)
    hinge_recorders = []
    if record:
        for eff in effectors:
            row = []
            for k in range(n):
                rec = eff.spinningBodyOutMsgs[k].recorder(bsk.macros.sec2nano(dt))
                sim.AddModelToTask("dynTask", rec)
                row.append(rec)
            hinge_recorders.append(row)
    return _finish(bsk, sim, sc, dt, record, keep, hinge_recorders)


def mujoco_model(n: int) -> str:
    """MJCF of the same system: free hub, two chains of hinge-jointed bodies."""
    s = segment(n)
    ix, iy, iz = HUB_INERTIA_KG_M2
    inertia = f"{s.inertia[0, 0]} {s.inertia[1, 1]} {s.inertia[2, 2]} 0 0 0"

    def chain(sign: float, tag: str) -> str:
        body = ""
        for k in reversed(range(n)):
            pos = f"{sign * ROOT_X_M} 0 0" if k == 0 else f"{-2 * s.half} 0 0"
            body = (f'<body name="{tag}_{k}" pos="{pos}"><joint name="{tag}_{k}" type="hinge" '
                    f'axis="0 1 0" stiffness="{HINGE_K}" damping="{HINGE_C}" springref="0"/>'
                    f'<inertial pos="{-s.half} 0 0" mass="{s.mass}" fullinertia="{inertia}"/>'
                    f"{body}</body>")  # fmt: skip
        return body

    return (f'<mujoco><option gravity="0 0 0"/><worldbody><body name="hub"><freejoint/>'
            f'<inertial pos="0 0 0" mass="{HUB_MASS_KG}" fullinertia="{ix} {iy} {iz} 0 0 0"/>'
            f'{chain(1.0, "pP")}{chain(-1.0, "pM")}</body></worldbody></mujoco>')  # fmt: skip


def build_mujoco(bsk, n: int, dt: float, record: bool) -> SimpleNamespace:
    """The MuJoCo back end, integrated by Basilisk's RK4 (high-order attitude step)."""
    sim = _sim(bsk, dt)
    scene = bsk.mujoco.MJScene(mujoco_model(n))
    scene.ModelTag = "hubMj"
    scene.extraEoMCall = True
    scene.highOrderAttitudeIntegration = True
    sim.AddModelToTask("dynTask", scene, 1)
    integrator = bsk.svIntegrators.svIntegratorRK4(scene)
    scene.setIntegrator(integrator)
    hub = scene.getBody("hub")
    recorder = None
    if record:
        recorder = hub.getOrigin().stateOutMsg.recorder(bsk.macros.sec2nano(dt))
        sim.AddModelToTask("dynTask", recorder, 0)
    sim.InitializeSimulation()
    hub.setAttitudeRate(list(OMEGA0_B))
    for tag in ("pP_0", "pM_0"):
        scene.getBody(tag).getScalarJoint(tag).setPosition(math.radians(ROOT_ANGLE_DEG))
    return SimpleNamespace(sim=sim, recorder=recorder, hinges=[],
                           keep=[scene, integrator, hub])  # fmt: skip


def _finish(bsk, sim, sc, dt, record, keep, hinge_recorders) -> SimpleNamespace:
    recorder = None
    if record:
        recorder = sc.scStateOutMsg.recorder(bsk.macros.sec2nano(dt))
        sim.AddModelToTask("dynTask", recorder)
    sim.InitializeSimulation()
    return SimpleNamespace(sim=sim, recorder=recorder, hinges=hinge_recorders, keep=keep)


ENGINES = {"nHinged": build_nhinged, "spinningBodyNDOF": build_ndof, "MuJoCo": build_mujoco}
"""Every Basilisk engine of the comparison, by the name the tables print."""


def engines(bsk) -> dict:
    """The engines the installed Basilisk offers (MuJoCo only if its wheel ships it)."""
    return {k: v for k, v in ENGINES.items() if k != "MuJoCo" or bsk.mujoco is not None}

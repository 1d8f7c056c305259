"""Plant-B tracking: linear design, observers (seed 001 eqs. 10-11), compensation, paths, robot, harness."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import expm

from compliance import metrics as M
from compliance import procedures
from compliance.model.config import load_plant
from compliance.errors import InputError
from compliance.model.vector_slots import S_PA, S_PB
from compliance.model.plant_vector import parameter_vector
from compliance.model.rest_state import initial_state
from compliance.simulation import Scenario
from compliance.plants import simulate
from compliance.simulation.profiles import sine
from compliance.procedures import path_tracking as tracking
from compliance.model import axis_design as design
from compliance.metrics.path_tracking import path_deviation, stick_slip_episodes
from tests.tracking.observer_run import observe
from compliance.tracking.paths import circle, read_path_csv, stroke_path, time_parameterise
from compliance.simulation.state_feedback_loop import AxisReference, simulate_axis

ROOT = Path(__file__).resolve().parents[2]
TS = 1e-3


@pytest.fixture(scope="module")
def cfg():
    return load_plant(ROOT / "models" / "plant-b.toml")


@pytest.fixture(scope="module")
def model(cfg):
    return design.axis_model(cfg)


# --------------------------------------------------------------------------- linear design
def test_linear_model_is_the_pneumatic_spring(cfg, model):
    # textbook model at rest (e.g. Richer & Hurmuzlu 2000): d1 = gamma/M (p_A A1^2/V_A + p_B A2^2/V_B),
    # d2 = c/M; the Jacobian is exact to the finite-difference round-off (the rhs is linear in v)
    P = parameter_vector(cfg)
    y = initial_state(cfg, P, 0.15)
    a1, a2, v0 = cfg.piston_area, cfg.rod_side_area, cfg.p("cylinder.dead_volume")
    va, vb = v0 + a1 * 0.15, v0 + a2 * 0.15
    d1 = 1.4 / 2.5 * (y[S_PA] * a1 * a1 / va + y[S_PB] * a2 * a2 / vb)
    assert model.d1 == pytest.approx(d1, rel=1e-6)
    assert model.d2 == pytest.approx(60.0 / 2.5, rel=1e-6)
    assert model.d0 == pytest.approx(0.0, abs=1e-9 * model.d1)  # shut critical-centre valve: no pressure feedback
    assert model.n0 > 0


def test_placed_poles(model):
    k = design.state_feedback_gains(model, 40.0, 0.7)
    poles = np.sort_complex(np.linalg.eigvals(model.a3 - model.b3 @ k[None, :]))
    want = np.sort_complex(design.design_poles(40.0, 0.7))
    assert np.allclose(poles, want, rtol=1e-8)


def _linear_run(model, u, a0=1.0):
    """Exact ZOH simulation of the (x, v, a) model; returns samples of x, v, a."""
    n = u.size
    big = np.zeros((4, 4))
    big[:3, :3] = model.a3
    big[:3, 3:] = model.b3
    phi = expm(big * TS)
    ad, bd = phi[:3, :3], phi[:3, 3]
    s = np.zeros((n, 3))
    s[0] = [0.15, 0.0, a0]
    for k in range(n - 1):
        s[k + 1] = ad @ s[k] + bd * u[k]
    return s


def test_acceleration_observer_converges_on_the_linear_model(model):
    obs = design.acceleration_observer(model, 400.0)
    assert obs.pole == pytest.approx(-400.0)
    rng = np.random.default_rng(3)
    u = np.repeat(rng.uniform(-0.05, 0.05, 40), 25)  # held command steps, 25 ms each
    s = _linear_run(model, u)
    a_hat = observe(obs, s[:, :2], u, TS)  # x1 = (x, v) measured, a^(0) = 0 while a(0) = 1 m/s^2
    err = np.abs(a_hat - s[:, 2])
    # initial error decays at the placed pole
    k = int(round(5.0 / 400.0 / TS))
    jerk = np.abs(np.diff(s[:, 2])) / TS
    # residual bound: the drive is a straight line between samples, the true x1 curves; the
    # deviation |s_v| * max|a'| * ts^2 / 8 passes the observer's low-pass of gain 1/|pole|
    bound = abs(obs.state_gain[1]) * jerk.max() * TS**2 / 8.0 / 400.0
    assert err[k] <= math.exp(-5.0) * 1.0 + 2 * bound
    assert err[k:].max() <= 2 * bound + 1e-3 * math.exp(-5.0)


def test_friction_observer_tracks_a_friction_step(model):
    obs = design.friction_observer(model, 100.0)
    m, a1 = model.mass, model.area_a
    n = 400
    up = np.full(n, 30.0 / a1)  # 30 N of pneumatic force, held
    f_true = np.where(np.arange(n) >= 100, 15.0, 0.0)  # friction steps to 15 N at sample 100
    v = np.zeros(n)
    for k in range(n - 1):  # v' = (A1 u_p - F)/M, constant over each sample: v is exactly piecewise linear
        v[k + 1] = v[k] + TS * (a1 * up[k] - f_true[k]) / m
    f_hat = observe(obs, v[:, None], up, TS)
    t = (np.arange(n) - 100) * TS
    expected = np.where(t >= 0, 15.0 * (1.0 - np.exp(-100.0 * np.clip(t, 0, None))), 0.0)
    # first-order-hold update is exact for piecewise-linear v: round-off only
    assert np.allclose(f_hat, expected, atol=1e-9 * 15.0)
    assert f_hat[100 + 30] == pytest.approx(15.0 * (1 - math.exp(-3.0)), rel=1e-9)  # 95 % after 3 time constants


# --------------------------------------------------------------------------- compiled loop
def test_pid_mode_reproduces_the_simulator(cfg):
    prof = sine(0.02, 0.5, 0.15, duration=1.0)
    df1 = simulate(cfg.replace(options={"controller.type": "pid"}), Scenario(1.0, 0.15, reference=prof))
    t = df1["time"].to_numpy()
    r = prof.at(t)
    df2 = simulate_axis(cfg, AxisReference(r, np.gradient(r, t), np.zeros_like(r)), mode="pid")
    for col in df1.columns:  # same kernels, same order of operations: bit-identical
        assert np.array_equal(df1[col].to_numpy(), df2[col].to_numpy()), col


def test_compensation_lowers_circle_tracking_error_and_stick_slip(cfg):
    with_c = tracking.run_procedure(cfg, "circle_tracking", radius=0.05, frequency=0.2, cycles=1)
    without = tracking.run_procedure(cfg, "circle_tracking", radius=0.05, frequency=0.2, cycles=1, without_compensation=True)
    pid = tracking.run_procedure(cfg, "circle_tracking", radius=0.05, frequency=0.2, cycles=1, pid=True)
    s1, s0, sp = with_c["summary"], without["summary"], pid["summary"]
    # the compensation must remove a substantial share of the error, not a round-off difference
    assert s1["path_rms_error"] < 0.7 * s0["path_rms_error"]
    assert s1["axis_rms_error"] < 0.7 * s0["axis_rms_error"]
    assert s1["stick_slip_fraction"] < s0["stick_slip_fraction"]
    # and the state feedback beats the PID of the same plant by an order of magnitude
    assert s0["path_rms_error"] < 0.1 * sp["path_rms_error"]
    assert with_c["notes"][0] == "controller: state feedback + friction compensation"


def test_static_gain_compensation_is_unstable(cfg):
    # the documented reason for the inverse-integrator form (docs/plant-b.md)
    t = np.arange(3001) * TS
    w = 2 * math.pi * 0.2
    ref = AxisReference(0.15 + 0.05 * np.sin(w * t), 0.05 * w * np.cos(w * t), -0.05 * w * w * np.sin(w * t))
    inv = simulate_axis(cfg, ref, compensation=True)
    stat = simulate_axis(cfg, ref, compensation=True, compensation_form="static")
    e_inv = M.tracking_errors(t, inv["position"], inv["reference"], 0.5)[0]
    e_stat = M.tracking_errors(t, stat["position"], stat["reference"], 0.5)[0]
    assert e_stat > 10 * e_inv


# --------------------------------------------------------------------------- paths
def test_circle_trajectory_respects_geometry_and_limits():
    tr = circle(0.05, 0.2, cycles=1, acceleration_limit=2.0)
    r = np.linalg.norm(tr.position[:, :2], axis=1)
    assert np.max(np.abs(r - 0.05)) < 1e-6 * 0.05  # spline through 720 points per turn
    speed = np.linalg.norm(tr.velocity, axis=1)
    assert speed.max() == pytest.approx(2 * math.pi * 0.2 * 0.05, rel=1e-6)
    assert speed[0] == 0.0 and speed[-1] < 2.0 * TS  # from rest to rest
    # velocity is the derivative of position: central differences agree to a_max * ts
    vnum = np.gradient(tr.position, tr.time, axis=0)
    assert np.max(np.abs(vnum - tr.velocity)) <= 2.0 * TS


def test_polyline_stops_at_corners_and_obeys_limits():
    pts = np.array([[0, 0, 0], [0.05, 0, 0], [0.05, 0.05, 0]])
    tr = time_parameterise(pts, speed_limit=0.1, acceleration_limit=1.0, sample_time=TS)
    speed = np.linalg.norm(tr.velocity, axis=1)
    assert speed.max() <= 0.1 * (1 + 1e-12)
    k = np.argmin(np.linalg.norm(tr.position - pts[1], axis=1))
    assert speed[k] < 1.0 * TS  # stops at the 90 deg corner (within one sample of the a-limit)
    acc = np.linalg.norm(tr.acceleration, axis=1)
    assert acc.max() <= 1.0 * (1 + 1e-9)


def test_shipped_character_and_csv_errors(tmp_path):
    pts = read_path_csv("jiang")
    assert pts.shape[1] == 3 and pts[:, 2].max() == pytest.approx(0.015)  # pen lifted 15 mm
    tr = stroke_path("jiang", speed_limit=0.05)
    # the limit is enforced on the 0.2 mm grid; between nodes |c'(s)| of a chord-parameterised
    # spline drifts by O((kappa ds)^2) ~ 1e-7 on these strokes
    assert np.linalg.norm(tr.velocity, axis=1).max() <= 0.05 * (1 + 1e-6)
    bad = tmp_path / "bad.csv"
    bad.write_text("x_mm,y_mm,z_mm\n1,2,3\n4,oops,6\n")
    with pytest.raises(InputError, match="line 3, column 'y_mm'"):
        read_path_csv(bad)
    bad.write_text("x_in,y_mm,z_mm\n1,2,3\n")
    with pytest.raises(InputError, match="unit 'in'"):
        read_path_csv(bad)


# --------------------------------------------------------------------------- metrics
def test_path_deviation_exact_distances():
    seg = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    pts = np.array([[0.5, 0.003, 0.004], [2.0, 0.0, 0.0]])
    assert np.allclose(path_deviation(pts, seg), [0.005, 1.0], rtol=1e-12)
    th = np.linspace(0, 2 * np.pi, 3601)
    circ = np.column_stack([0.05 * np.cos(th), 0.05 * np.sin(th), 0 * th])
    # a chord of 0.1 deg sags by R(1 - cos(0.05 deg)) = 1.9e-8 m: below 1e-7 m
    assert path_deviation(np.array([[0.051, 0.0, 0.0], [0.0, 0.0499, 0.0]]), circ) == pytest.approx([0.001, 0.0001], abs=1e-7)


def test_stick_slip_episode_detection():
    t = np.arange(0, 1.0, TS)
    vr = np.full(t.size, 0.01)  # reference moves at 10 mm/s throughout
    x = 0.01 * t
    stuck = (t >= 0.4) & (t < 0.5)
    x = np.where(stuck, 0.01 * 0.4, np.where(t >= 0.5, 0.01 * (t - 0.1), x))  # stops for 0.1 s, then goes on
    eps = stick_slip_episodes(t, x, vr)
    assert len(eps) == 1
    # the 10 ms centred speed window blurs each edge by up to half its span
    assert eps[0].t_start == pytest.approx(0.4, abs=0.006) and eps[0].duration == pytest.approx(0.1, abs=0.012)


# --------------------------------------------------------------------------- harness wiring
def test_requirement_file_runs_through_the_registry(cfg):
    from compliance.metrics.catalogue import METRICS
    from compliance.procedures.kinds import TRACKING
    from compliance.requirements import load_requirements

    rs = load_requirements(ROOT / "requirements" / "tracking-robot.toml")
    assert {p.kind for p in rs.procedures.values()} <= set(TRACKING)
    assert {r.metric for r in rs.requirements} <= {m for m, info in METRICS.items() if set(info.kinds) & set(TRACKING)}
    req = next(r for r in rs.requirements if r.id == "TR-AXIS-RMS")
    out = procedures.run(cfg, rs.procedures["axis-sine-50mm"], rs.operating_points["workspace-centre"], [(req.metric, {})])
    assert out.error is None
    vals = [s.value for s in out.samples["axis_rms_error"]]
    assert len(vals) == 1 and 0 < vals[0] < 1e-3
    assert out.traces and "reference" in out.traces[0]


def test_run_procedure_rejects_bad_input(cfg):
    with pytest.raises(InputError, match="not known"):
        tracking.run_procedure(cfg, "square_tracking")
    with pytest.raises(InputError, match="unknown setting 'radios'"):
        tracking.run_procedure(cfg, "circle_tracking", radios=0.05, frequency=0.2)
    with pytest.raises(InputError, match="outside the stroke"):
        tracking.run_procedure(cfg, "circle_tracking", radius=0.2, frequency=0.2)
    with pytest.raises(InputError, match="missing setting 'amplitude'"):
        tracking.run_procedure(cfg, "axis_tracking", frequency=0.2)

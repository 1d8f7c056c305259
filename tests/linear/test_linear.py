"""Linearised analysis: Jacobian vs hand-derived physics, loop algebra, margins, maps, CLI exit codes."""

from __future__ import annotations

import json
import math

import control
import numpy as np
import pytest

from compliance.cli import main
from compliance.model.config import load_plant
from compliance.model.pid_controller import first_order_filter_gain, pid_step
from compliance.errors import InputError
from compliance.linear.analysis import analyse, close_loop, linear_metric, margins, pid_controller
from compliance.linear.maps import nonlinear_step, operating_map, viscous_friction_variant
from compliance.linear.trim import linearise_plant, trim


@pytest.fixture(scope="module")
def cfg():
    return load_plant("plant-a")


def _geometry(cfg, x):
    at = cfg.piston_area + cfg.rod_side_area  # tandem: A = A_cap + A_rod (reference-plant.md)
    v0 = cfg.p("cylinder.dead_volume")
    L = cfg.p("cylinder.stroke")
    return at, 2 * v0 + at * x, 2 * v0 + at * (L - x)


def _iso_w(a, b):
    """ISO 6358 flow function (seed 000 eq. 2), written out independently of the package."""
    return 1.0 if a <= b else math.sqrt(1.0 - ((a - b) / (1.0 - b)) ** 2)


# ---------------------------------------------------------------------------------------- physics
@pytest.mark.parametrize("x, load", [(0.08, None), (0.02, 11400.0), (0.15, -2300.0), (0.0, 5000.0), (0.16, "curve")])
def test_jacobian_is_the_pneumatic_spring(cfg, x, load):
    op = trim(cfg, x, load)
    A, B, C, names, _ = linearise_plant(op, cfg)
    assert names[:4] == ["position", "velocity", "pressure_a", "pressure_b"]
    at, va, vb = _geometry(cfg, x)
    gamma, m = cfg.p("air.heat_capacity_ratio"), cfg.p("cylinder.moving_mass")
    k_hand = gamma * at**2 * (op.pressure_a / va + op.pressure_b / vb)  # k = gamma A^2 (p_A/V_A + p_B/V_B)
    iv, ia, ib = names.index("velocity"), names.index("pressure_a"), names.index("pressure_b")
    k_jac = -m * (A[iv, ia] * A[ia, iv] + A[iv, ib] * A[ib, iv])
    # the rows are linear in the stepped state, so central differences are exact up to rounding (~1e-9)
    assert k_jac == pytest.approx(k_hand, rel=1e-6)
    assert A[iv, iv] == pytest.approx(-2 * cfg.p("friction.viscous_coefficient") / m, rel=1e-6)  # viscous part, 2 cylinders
    assert op.pressure_a - op.pressure_b == pytest.approx(op.load_force / at, rel=1e-12)  # trim balances the load
    assert op.residual < 1e-9  # at rest: viscous friction only, valve shut


def test_input_column_is_the_iso6358_flow_gain(cfg):
    x, load = 0.08, 5000.0
    op = trim(cfg, x, load)
    A, B, C, names, _ = linearise_plant(op, cfg, gain="opening")
    at, va, vb = _geometry(cfg, x)
    p = cfg.params
    grt = p["air.heat_capacity_ratio"] * p["air.gas_constant"] * p["air.supply_temperature"]
    c_rho = p["valve.sonic_conductance"] * p["air.reference_density"] * math.sqrt(p["air.reference_temperature"] / p["air.supply_temperature"])
    per_volt = 1.0 / (p["controller.compensation_slope_positive"] * (p["valve.saturation_voltage"] - p["valve.dead_zone_positive"]))
    ps, patm, b = p["air.supply_pressure"], p["air.atmospheric_pressure"], p["valve.critical_pressure_ratio"]
    dpa = grt / va * c_rho * ps * _iso_w(op.pressure_a / ps, b) * per_volt  # P -> A filling, seed 000 eqs. (1), (4)
    dpb = -grt / vb * c_rho * op.pressure_b * _iso_w(patm / op.pressure_b, b) * per_volt  # B -> T exhausting
    # flows are proportional to the opening: the 1e-4 probe opening measures the slope exactly
    assert B[names.index("pressure_a"), 0] == pytest.approx(dpa, rel=1e-6)
    assert B[names.index("pressure_b"), 0] == pytest.approx(dpb, rel=1e-6)
    assert B[names.index("position"), 0] == 0.0 and B[names.index("velocity"), 0] == 0.0


def test_velocity_gain_and_pneumatic_mode(cfg):
    # steady ramp of the linear model at mid stroke: A v (p_A/V_A + p_B/V_B) = R T (q_A'/V_A + q_B'/V_B) per volt
    a = analyse(cfg, 0.08, None, detail=False)
    at, va, vb = _geometry(cfg, 0.08)
    p = cfg.params
    ps, patm, b = p["air.supply_pressure"], p["air.atmospheric_pressure"], p["valve.critical_pressure_ratio"]
    pa = pb = a.op.pressure_a
    c_rho = p["valve.sonic_conductance"] * p["air.reference_density"]
    fill, vent = c_rho * ps * _iso_w(pa / ps, b), c_rho * pb * _iso_w(patm / pb, b)
    k_mean = 0.5 * sum(1.0 / (p["valve.saturation_voltage"] - p[f"valve.dead_zone_{s}"]) for s in ("positive", "negative"))
    rt = p["air.gas_constant"] * p["air.supply_temperature"]
    kq = rt * (fill / va + vent / vb) / (at * (pa / va + pb / vb)) * k_mean
    assert a.figures["plant_velocity_gain"] == pytest.approx(kq, rel=1e-6)
    # the pneumatic pair is the spring-mass pair with the viscous damping b_total/(2 sqrt(k M))
    assert a.figures["natural_frequency_hz"] == pytest.approx(a.figures["natural_frequency_analytic_hz"], rel=1e-6)
    assert a.figures["pneumatic_damping_ratio"] == pytest.approx(a.figures["viscous_damping_ratio_analytic"], rel=1e-6)
    # the common level of p_A and p_B is not seen from the position: one state less in the minimal plant
    assert a.plant.nstates == 4 and a.plant_minimal.nstates == 3


# ---------------------------------------------------------------------------------------- loop algebra
def _nearest_match(a, b):
    a, b = list(np.sort_complex(a)), list(b)
    for r in a:
        j = int(np.argmin([abs(r - q) for q in b]))
        assert abs(r - b[j]) <= 1e-6 * max(1.0, abs(r)), (r, b[j])
        b.pop(j)


def test_closed_loop_poles_of_a_hand_built_loop(cfg):
    kq, wn, z = 0.04, 80.0, 0.3
    n, d = [kq * wn**2], [1.0, 2 * z * wn, wn**2, 0.0]  # G = K_q w^2 / (s (s^2 + 2 z w s + w^2))
    T, _ = close_loop(cfg, control.ss(control.tf(n, d)))
    kp, ki, kd = cfg.p("controller.kp"), cfg.p("controller.ki"), cfg.p("controller.kd")
    wf = 2 * math.pi * cfg.p("controller.filter_cutoff")
    # 1 + C_y G = 0 with C_y = K_P + K_I/s + K_D s w_f/(s + w_f):
    # s (s + w_f) d + [K_P s (s + w_f) + K_I (s + w_f) + K_D w_f s^2] n = 0
    sw = np.polymul([1.0, 0.0], [1.0, wf])
    ctrl = np.polyadd(np.polyadd(kp * sw, ki * np.array([1.0, wf])), kd * wf * np.array([1.0, 0.0, 0.0]))
    char = np.polyadd(np.polymul(sw, d), np.polymul(ctrl, n))
    _nearest_match(np.roots(char), T.poles())
    # sampled loop: C_y(z) = K_P + K_I T_s z/(z - 1) + (K_D alpha/T_s)(z - 1)/(z - beta), from pid_step
    ts = cfg.p("controller.sample_time")
    al = first_order_filter_gain(cfg.p("controller.filter_cutoff"), ts)
    be = 1.0 - al
    Gd = control.tf(control.c2d(control.ss(control.tf(n, d)), ts, "zoh"))
    nd, dd = np.ravel(Gd.num[0][0]), np.ravel(Gd.den[0][0])
    zz = np.polymul([1.0, -1.0], [1.0, -be])
    cz = np.polyadd(np.polyadd(kp * zz, ki * ts * np.polymul([1.0, 0.0], [1.0, -be])), kd * al / ts * np.polymul([1.0, -1.0], [1.0, -1.0]))
    Td, _ = close_loop(cfg, control.ss(control.tf(n, d)), discrete=True)
    _nearest_match(np.roots(np.polyadd(np.polymul(dd, zz), np.polymul(nd, cz))), Td.poles())


def test_discrete_controller_matches_the_simulator_pid(cfg):
    kp, ki, kd = cfg.p("controller.kp"), cfg.p("controller.ki"), cfg.p("controller.kd")
    ts = cfg.p("controller.sample_time")
    al = first_order_filter_gain(cfg.p("controller.filter_cutoff"), ts)
    rng = np.random.default_rng(1)
    r, xm = rng.normal(0, 1e-3, 60), rng.normal(0, 1e-3, 60)
    xm[0] = 0.0  # the simulator starts its filter at the first measurement; the state space at 0
    u_sim, integ, xf = [], 0.0, xm[0]
    for k in range(60):  # the loop of compliance.simulation.pid_loop.simulate_core
        x_new = xf + al * (xm[k] - xf)
        rate = (x_new - xf) / ts
        xf = x_new
        u, integ = pid_step(r[k] - xm[k], rate, integ, kp, ki, kd, ts)
        u_sim.append(u)
    k = pid_controller(cfg, discrete=True)
    resp = control.forced_response(k, np.arange(60) * ts, np.vstack([r, xm]))
    assert np.allclose(resp.outputs, u_sim, rtol=1e-10, atol=1e-12)


def test_margins_of_a_textbook_loop():
    # L = 1/(s (s+1)(s+2)): phase -180 deg at w = sqrt(2), |L| = 1/6 there -> GM = 6 (15.56 dB)
    m = margins(control.tf([1.0], [1.0, 3.0, 2.0, 0.0]))
    assert m["gain_margin_db"] == pytest.approx(20 * math.log10(6.0), abs=1e-3)
    assert m["phase_crossover_hz"] == pytest.approx(math.sqrt(2) / (2 * math.pi), rel=1e-4)
    from scipy.optimize import brentq

    wc = brentq(lambda w: w * math.hypot(w, 1) * math.hypot(w, 2) - 1.0, 0.1, 1.0)  # |L(j wc)| = 1
    pm = 180.0 - 90.0 - math.degrees(math.atan(wc) + math.atan(wc / 2))
    assert m["phase_margin_deg"] == pytest.approx(pm, abs=1e-3)
    assert m["gain_crossover_hz"] == pytest.approx(wc / (2 * math.pi), rel=1e-4)


# ---------------------------------------------------------------------------------------- maps and cross-check
def test_map_is_symmetric_about_mid_stroke_for_a_symmetric_actuator(cfg):
    sym = cfg.replace(params={"valve.dead_zone_negative": 0.61, "controller.compensation_dead_zone_negative": 0.61})
    L = cfg.p("cylinder.stroke")
    m = operating_map(sym, positions=[0.2 * L, 0.35 * L, 0.65 * L, 0.8 * L], loads=[0.0], curve=False)
    for name in ("time_constant", "gain_margin_db", "phase_margin_deg", "bandwidth_hz", "damping_ratio"):
        row = m.values[name][0]
        # the mirrored plant is the same system with A and B swapped: equal to rounding
        assert row[0] == pytest.approx(row[3], rel=1e-6), name
        assert row[1] == pytest.approx(row[2], rel=1e-6), name
    tau = m.values["time_constant"][0]
    assert abs(tau[0] - tau[1]) > 1e-3 * tau[1]  # the position does change the figure: the test can fail
    assert json.dumps(m.to_dict())


def test_linear_and_nonlinear_agree_without_friction_and_dead_zone(cfg):
    # With friction reduced to its viscous part and no dead zone, only flow nonlinearity over a
    # 1 % step separates the two models; pressures move by ~1 %, so the time constants agree to ~1 %.
    zero = {f"{k}_{s}": 0.0 for k in ("valve.dead_zone", "controller.compensation_dead_zone") for s in ("positive", "negative")}
    plain = viscous_friction_variant(cfg.replace(params=zero))
    tau_lin = analyse(plain, 0.08, 5000.0, gain="opening", detail=False).figures["time_constant"]
    tau_nl = nonlinear_step(plain, 0.08, 5000.0, 0.01).time_constant
    assert tau_nl == pytest.approx(tau_lin, rel=0.03)


def test_linear_metric_matches_analysis(cfg):
    a = analyse(cfg, 0.136, 11400.0, detail=False)
    assert linear_metric(cfg, "time_constant", 0.136, "11.4 kN") == pytest.approx(a.figures["time_constant"], rel=1e-12)
    assert linear_metric(cfg, "gain_margin_db", 0.136, 11400.0) == pytest.approx(a.figures["gain_margin_db"], rel=1e-12)
    with pytest.raises(InputError, match="not known"):
        linear_metric(cfg, "tau", 0.136, 11400.0)


# ---------------------------------------------------------------------------------------- bad input
def test_trim_rejects_positions_and_loads_outside_the_actuator(cfg):
    at = cfg.piston_area + cfg.rod_side_area
    cap = (cfg.p("air.supply_pressure") - cfg.p("air.atmospheric_pressure")) * at  # (p_s - p_atm)(A_cap + A_rod)
    trim(cfg, 0.08, 0.999 * cap)
    trim(cfg, 0.08, -0.999 * cap)
    for load in (1.001 * cap, -1.001 * cap):
        with pytest.raises(InputError, match="cannot be held"):
            trim(cfg, 0.08, load)
    for x in (-1e-3, 0.161):
        with pytest.raises(InputError, match="outside the stroke"):
            trim(cfg, x, None)


@pytest.mark.parametrize("argv", [
    ["linear", "plant-a", "--at", "200 mm"],
    ["linear", "plant-a", "--at", "-1 mm"],
    ["linear", "plant-a", "--at", "lots"],
    ["linear", "plant-a", "--load", "20 kN"],
    ["linear", "plant-a", "--load", "-20 kN"],
    ["linear", "plant-a", "--load", "12 bar"],
    ["linear", "plant-a", "--plot", "out.txt"],
    ["linear", "no-such-plant.toml"],
])
def test_cli_bad_input_exits_2(argv, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("govcheck linear: error:") and "Traceback" not in err


def test_cli_writes_json(tmp_path, capsys):
    out = tmp_path / "lin.json"
    assert main(["linear", "plant-a", "--at", "136 mm", "--load", "11.4 kN", "--json", str(out)]) == 0
    d = json.loads(out.read_text())
    a = d["analysis"]
    assert a["operating_point"]["position"] == pytest.approx(0.136)
    assert a["operating_point"]["load_force"] == pytest.approx(11400.0)
    assert len(a["bode"]["frequency_hz"]) == len(a["bode"]["loop_magnitude_db"]) > 10
    assert all(len(p) == 2 for p in a["poles"]["closed_loop"])
    assert "time constant" in capsys.readouterr().out


def test_governor_rates_recover_the_flow_control_setting(cfg):
    from compliance.linear.governor_model import governor_parameters

    # plant-a.toml sets both meter-out throttles for 5 s full strokes at 5.7 kN from the end stops
    # (seed 000 section 5.2): 0.2 pu/s; 10 % covers the 25-75 % extrapolation against the paper's
    # end-to-end definition. From rest the exhaust side starts at (p_s + p_atm)/2 instead of
    # atmosphere, so the same throttles let the gate move faster: UO/UC exceed the end-stop rates.
    g = governor_parameters(cfg, stroke_load=5700.0)
    ends = {m["direction"]: m["rate_pu_per_s"] for m in g.end_stop}
    assert ends["opening"] == pytest.approx(0.2, rel=0.10)
    assert ends["closing"] == pytest.approx(0.2, rel=0.10)
    assert g.UO > 1.3 * ends["opening"] and -g.UC > 1.3 * ends["closing"]
    assert g.VELM == max(g.UO, -g.UC)
    assert 0.05 < g.Tg < 1.0 and (g.GMAX, g.GMIN) == (1.0, 0.0)
    assert json.loads(g.to_json())["parameters"]["Tg"] == pytest.approx(g.Tg)


def test_trim_with_a_compliant_linkage_shares_the_load_like_the_rest_state(cfg):
    """Each cylinder carries half the gate-ring load: 2A1 at rest has f1 + K d = F/2 (no friction in
    the trim), the same deflection the simulator's rest state gives."""
    from compliance.model.plant_vector import parameter_vector
    from compliance.model.rest_state import initial_state
    from compliance.effects.linkage_compliance import S_X2
    from compliance.model.vector_slots import S_X

    k, load = 7e4, 3000.0
    lc = cfg.replace(effects={"linkage_compliance": {"stiffness": k, "damping": 500.0}})
    op = trim(lc, 0.02, load)
    f1 = op.pressure_a * lc.piston_area - op.pressure_b * lc.rod_side_area
    d = op.state[S_X2] - op.state[S_X]
    assert f1 + k * d == pytest.approx(0.5 * load, rel=1e-9)
    y = initial_state(lc, parameter_vector(lc, load=load), 0.02, (op.pressure_a, op.pressure_b))
    assert y[S_X2] - y[S_X] == pytest.approx(d, rel=1e-9)


def test_cli_plot_draws_the_reports_figures(tmp_path, monkeypatch, capsys):
    """--plot is the report's Bode, pole and step figures of the analysis (figures_linear), not a drawing of its own."""
    import compliance.report.figures_linear as F

    drawn = []
    for name in ("draw_bode", "draw_poles"):
        real = getattr(F, name)
        monkeypatch.setattr(F, name, lambda *a, _real=real, _name=name, **k: drawn.append(_name) or _real(*a, **k))
    out = tmp_path / "lin.svg"
    assert main(["linear", "plant-a", "--at", "80 mm", "--plot", str(out), "-q"]) == 0
    text = out.read_text()
    assert drawn == ["draw_bode", "draw_poles"]
    assert "|L| [dB]" in text and "\u03c4 = 0.25 s" in text and "predicted 8 mm step" in text  # the report's labels

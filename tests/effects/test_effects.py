"""Each declared effect, switched on in the model, moves the signals the way its physics says.

Exact checks use closed volumes (the piston held on its x = 0 end stop by a closing load
larger than (p_s - p_atm) * A, the valve shut inside its dead zone) where the effect's own
equation can be integrated by hand, or the right-hand side itself at one state. Closed-loop
checks compare the same test with and without the effect, with bounds taken from the valve's
dead band or the effect's parameters.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from compliance.model.config import load_plant
from compliance.effects.linkage_compliance import S_X2
from compliance.model.vector_slots import A_FRIC, A_LOAD, N_AUX, N_STATES, S_V
from compliance.model.assembly import plant_rhs
from compliance.model.plant_vector import load_curve_arrays, parameter_vector
from compliance.model.rest_state import initial_state
from compliance.simulation.profiles import Profile, steps
from compliance.simulation import Scenario
from compliance.plants import simulate

R, GAMMA, TS = 287.0, 1.4, 293.15
HOLD_LOAD = 30000.0  # N: more than (8 - 1.013) bar * 0.0237 m^2 = 16.6 kN, the piston stays on x = 0


@pytest.fixture(scope="module")
def cfg():
    return load_plant("plant-a")


T_OPEN = 0.1  # s: the valve opens once the piston has settled into the end stop


def _charge_then_close(cfg, duration=3.0, open_for=0.15, volts=2.0, p0=(3e5, 3e5)):
    """Valve opened P->A for ``open_for`` s at the x = 0 stop, then shut (0 V is inside the dead zone)."""
    t1 = T_OPEN + open_for
    cmd = Profile(np.array([0.0, T_OPEN, T_OPEN, t1, t1]), np.array([0.0, 0.0, volts, volts, 0.0]))
    return simulate(cfg, Scenario(duration=duration, initial_position=0.0, command=cmd, load=HOLD_LOAD, initial_pressures=p0))


def _volumes(cfg, x=0.0):
    """Chamber volumes of the tandem pair at position x (reference-plant.md, decoded eq. 4)."""
    v0 = cfg.p("cylinder.dead_volume")
    at = cfg.piston_area + cfg.rod_side_area
    return 2 * v0 + at * x, 2 * v0 + at * (cfg.p("cylinder.stroke") - x)


def _settled(df, t0=0.1):
    """The run after the piston has settled into the end stop (it presses ~0.2 mm into it)."""
    part = df[df.time >= t0].reset_index(drop=True)
    # the stop (1e8 N/m) gives a few um as the pressures change: A_t * 10 um is 1e-4 of V_A, below the 1e-3 tolerances
    assert np.ptp(part.position_true.to_numpy()) < 1e-5
    return part


def test_heat_transfer_relaxes_pressure_after_a_stop(cfg):
    """Closed chamber, no flow: T - T_s and p - p_inf decay with tau = m c_v / hA (energy equation)."""
    ha = 5.0
    df = _charge_then_close(cfg.replace(effects={"heat_transfer": {"conductance": ha}}))
    base = _charge_then_close(cfg)
    t = df.time.to_numpy()
    after = t > T_OPEN + 0.3
    pa = df.pressure_a.to_numpy()[after]
    # without the effect the gas stays at T_s: the pressure holds once the valve shuts
    pb = base.pressure_a.to_numpy()[after]
    assert np.ptp(pb) < 1.0
    # with it the compressed, heated charge cools: the pressure falls after the stop
    assert pa[0] - pa[-1] > 1e3
    va, _ = _volumes(cfg, df.position_true.iloc[-1])
    m = pa[0] * va / (R * df.temperature_a.to_numpy()[after][0])
    tau = m * R / (GAMMA - 1.0) / ha  # m c_v / hA, c_v = R / (gamma - 1)
    p_inf = pa[-1] - (pa[0] - pa[-1]) * math.exp(-(t[after][-1] - t[after][0]) / tau) / (1 - math.exp(-(t[after][-1] - t[after][0]) / tau))
    k = int(np.searchsorted(t[after] - t[after][0], tau))
    ratio = (pa[k] - p_inf) / (pa[0] - p_inf)
    assert ratio == pytest.approx(math.exp(-1.0), abs=0.03)  # one time constant: RK4 at 0.2 ms is far more accurate


def test_internal_leakage_equalises_chambers_at_the_predicted_rate(cfg):
    """Valve shut, volumes fixed: d(p_A - p_B)/dt = -gamma R T k (1/V_A + 1/V_B) (p_A - p_B); p_A V_A + p_B V_B holds."""
    k = 2e-10
    c = cfg.replace(effects={"internal_leakage": {"conductance": k}})
    df = _settled(simulate(c, Scenario(duration=2.0, initial_position=0.0, command=Profile.constant(0.0), load=HOLD_LOAD,
                                       initial_pressures=(6e5, 3e5))))
    va, vb = _volumes(cfg, df.position_true.iloc[0])
    dp = (df.pressure_a - df.pressure_b).to_numpy()
    t = df.time.to_numpy() - df.time.iloc[0]
    rate = GAMMA * R * TS * k * (1 / va + 1 / vb)
    assert dp[-1] / dp[0] == pytest.approx(math.exp(-rate * t[-1]), rel=1e-3)  # integrator error << 1e-3
    inventory = df.pressure_a.to_numpy() * va + df.pressure_b.to_numpy() * vb
    # d(pV)/dt = gamma R T q - (gamma - 1) p dV/dt: only the few-um creep into the stop changes the inventory
    creep = (GAMMA - 1.0) * 6e5 * (cfg.piston_area + cfg.rod_side_area) * np.ptp(df.position_true.to_numpy())
    assert np.ptp(inventory) < 2.0 * creep + 1e-9 * inventory[0]


def test_internal_leakage_keeps_the_valve_feeding_a_held_load(cfg):
    """Holding 9.5 kN: without a leak the valve ends shut; with one it must keep feeding side A."""
    sc = Scenario(duration=6.0, initial_position=0.05, reference=Profile.constant(0.05), load=9500.0)
    tail = slice(-3000, None)
    off = simulate(cfg, sc)
    on = simulate(cfg.replace(effects={"internal_leakage": {"conductance": 3e-10}}), sc)
    assert np.all(off.opening.to_numpy()[tail] == 0.0)
    assert np.mean(on.opening.to_numpy()[tail]) > 0.0  # net P->A opening replaces the leaked air
    assert np.mean(on.valve_command.to_numpy()[tail]) > np.mean(off.valve_command.to_numpy()[tail])


def test_external_leakage_drains_both_chambers_to_atmosphere(cfg):
    """Valve shut: d(p - p_atm)/dt = -gamma R T k (p - p_atm) / V on each side."""
    k = 2e-10
    c = cfg.replace(effects={"external_leakage": {"conductance": k}})
    df = _settled(simulate(c, Scenario(duration=2.0, initial_position=0.0, command=Profile.constant(0.0), load=HOLD_LOAD,
                                       initial_pressures=(6e5, 3e5))))
    va, vb = _volumes(cfg, df.position_true.iloc[0])
    patm = cfg.p("air.atmospheric_pressure")
    span = df.time.iloc[-1] - df.time.iloc[0]
    for col, v in (("pressure_a", va), ("pressure_b", vb)):
        p = df[col].to_numpy()
        assert (p[-1] - patm) / (p[0] - patm) == pytest.approx(math.exp(-GAMMA * R * TS * k / v * span), rel=1e-3)


def test_supply_droop_lowers_supply_pressure_during_a_move_and_recovers(cfg):
    """The valve's draw empties the reservoir; the regulator refills it with tau = V / (R T k_reg)."""
    vol, kreg = 0.01, 1e-7
    c = cfg.replace(effects={"supply_droop": {"reservoir_volume": vol, "regulator_conductance": kreg}})
    df = simulate(c, Scenario(duration=5.0, initial_position=0.05, reference=steps("10%@0.5s", 0.05, 0.16), load=3000.0))
    ps = df.supply_pressure.to_numpy()
    nominal = cfg.p("air.supply_pressure")
    assert nominal - ps.min() > 5e3  # the move draws ~10 g of air from a 10 L reservoir: tens of kPa
    assert np.all(simulate(cfg, Scenario(duration=1.0, initial_position=0.05, reference=steps("10%@0.5s", 0.05, 0.16),
                                         load=3000.0)).supply_pressure == nominal)
    tau = vol / (R * TS * kreg)
    k_min = int(np.argmin(ps))
    late = int(np.searchsorted(df.time.to_numpy(), df.time.iloc[k_min] + 3 * tau))
    if late < ps.size:  # after three time constants (valve shut again) the deficit is below ~5 % (+ the residual draw)
        assert nominal - ps[late] < 0.1 * (nominal - ps.min())


def test_valve_offset_shifts_the_holding_command(cfg):
    """At rest the valve is shut, so command + offset lies in the dead band (-zme, zmd)."""
    off = 1.0
    sc = Scenario(duration=4.0, initial_position=0.08, reference=steps("2%@0.5s", 0.08, 0.16), load=2000.0)
    df = simulate(cfg.replace(effects={"valve_offset": {"offset": off}}), sc)
    tail = df.iloc[-1000:]
    zmd = cfg.p("valve.dead_zone_positive")
    zme = cfg.p("valve.dead_zone_negative")
    assert np.all(tail.opening == 0.0)
    u = tail.valve_command.to_numpy()
    assert u.max() <= zmd - off + 1e-9 and u.min() >= -zme - off - 1e-9


def test_sensor_lag_delays_the_measured_position(cfg):
    """At constant speed a first-order lag tau plus a delay t_d put the reading (tau + t_d) * v behind."""
    tau, td = 0.01, 0.005
    c = cfg.replace(effects={"sensor_lag": {"time_constant": tau, "delay": td}})
    df = simulate(c, Scenario(duration=0.6, initial_position=0.04, command=Profile.constant(3.0), load=2000.0))
    part = df[(df.time > 0.35) & (df.time < 0.55)]
    v = part.velocity.to_numpy()
    assert np.ptp(v) < 0.05 * np.mean(v)  # steady speed, so the lag is (tau + td)*v
    lag = np.mean((part.position_true - part.position).to_numpy() / v)
    assert lag == pytest.approx(tau + td, rel=0.03)


def test_valve_dynamics_delay_the_pressure_response(cfg):
    """A command step reaches the chamber only after the valve's delay and spool lag."""
    td = 0.01
    c = cfg.replace(effects={"valve_dynamics": {"natural_frequency": 100.0, "damping": 0.7, "delay": td}})

    def first_rise(conf):
        df = _charge_then_close(conf, duration=0.4, open_for=0.3)
        t = df.time.to_numpy()
        p = df.pressure_a.to_numpy()
        k0 = int(np.searchsorted(t, T_OPEN))
        return t[k0 + np.argmax(p[k0:] > p[k0] + 1e3)] - T_OPEN

    assert first_rise(c) - first_rise(cfg) > td  # delay plus part of the spool's rise


def test_valve_dynamics_stage_spool_moves_in_the_dead_band_opening_does_not(cfg):
    """Spool stage: the filter follows the command even inside the dead band (the spool
    travels through its overlap); opening stage: it follows the opening, which is zero there."""
    from compliance.effects.valve_dynamics import S_SP, S_SV
    from compliance.model.assembly import valve_lag_input

    vd = {"valve_dynamics": {"natural_frequency": 50.0, "damping": 0.7, "delay": 0.0}}
    u = cfg.p("valve.centre_voltage") + 0.5 * cfg.p("valve.dead_zone_positive")  # inside the dead band
    lx, ly = load_curve_arrays(cfg)
    rates = {}
    for stage in ("spool", "opening"):
        c = cfg.replace(effects=vd, options={"valve.dynamics_stage": stage})
        P = parameter_vector(c, load=0.0)
        y = initial_state(c, P, 0.08)
        y[S_SP] = valve_lag_input(P, cfg.p("valve.centre_voltage"))
        dy = np.zeros(N_STATES)
        plant_rhs(y, P, u, lx, ly, dy, np.zeros(N_AUX))
        rates[stage] = dy[S_SV]
    assert rates["spool"] == pytest.approx(50.0 ** 2 * 0.5 * cfg.p("valve.dead_zone_positive"), rel=1e-9)
    assert rates["opening"] == 0.0


def test_valve_dynamics_stages_linearise_alike(cfg):
    """A linear valve gain commutes with the valve's lag, so both stages give one linear model."""
    import control

    from compliance.linear.analysis import analyse

    vd = {"valve_dynamics": {"natural_frequency": 150.0, "damping": 0.7, "delay": 0.002}}
    poles = []
    for stage in ("spool", "opening"):
        c = cfg.replace(effects=vd, options={"valve.dynamics_stage": stage})
        poles.append(np.sort_complex(control.poles(analyse(c, 0.08, 5700.0).closed_loop)))
    np.testing.assert_allclose(poles[0], poles[1], rtol=1e-9)


def test_line_dynamics_delay_the_chamber_pressure(cfg):
    """A hose volume and restriction between valve and chamber slow the chamber's first rise."""
    c = cfg.replace(effects={"line_dynamics": {"volume": 1e-3, "conductance": 2e-8}})

    def first_rise(conf):
        df = _charge_then_close(conf, duration=0.4, open_for=0.3)
        t = df.time.to_numpy()
        p = df.pressure_a.to_numpy()
        k0 = int(np.searchsorted(t, T_OPEN))
        return t[k0 + np.argmax(p[k0:] > p[k0] + 1e3)] - T_OPEN

    assert first_rise(c) > first_rise(cfg) + 0.002


def _rhs(cfg, y, u=0.0, load=0.0):
    P = parameter_vector(cfg, load=load)
    lx, ly = load_curve_arrays(cfg)
    dy = np.zeros(N_STATES)
    aux = np.zeros(N_AUX)
    plant_rhs(y, P, u, lx, ly, dy, aux)
    return dy, aux, P


def test_pressure_dependent_friction_scales_both_levels_by_one_plus_k_times_mean_gauge_pressure(cfg):
    """Sliding friction F = n (g(v) (1 + k (mean(p_A, p_B) - p_atm)) + b v): both levels scale, the
    Stribeck shape and the viscous term do not (variable-viscous map: no bristle state)."""
    c0 = cfg.replace(options={"friction.model": "variable_viscous"})
    k = 1e-6  # 0.1 per bar
    c1 = c0.replace(effects={"pressure_dependent_friction": {"coefficient": k}})
    P = parameter_vector(c0, load=0.0)
    v = 0.02
    for pa, pb in ((6e5, 4e5), (3e5, 2e5)):
        y = initial_state(c0, P, 0.08, (pa, pb))
        y[S_V] = v
        _, a0, _ = _rhs(c0, y)
        _, a1, _ = _rhs(c1, y)
        gauge = 0.5 * (pa + pb) - cfg.p("air.atmospheric_pressure")
        b = cfg.p("friction.viscous_coefficient")
        g0 = a0[A_FRIC] / 2 - b * v  # per cylinder, without the viscous part (two cylinders, tandem)
        rs = math.exp(-v / cfg.p("friction.stribeck_velocity"))
        assert g0 == pytest.approx(cfg.p("friction.coulomb_force") + (cfg.p("friction.static_force")
                                                                      - cfg.p("friction.coulomb_force")) * rs, rel=1e-9)
        assert a1[A_FRIC] == pytest.approx(2 * (g0 * (1 + k * gauge) + b * v), rel=1e-9)


def test_position_dependent_load_adds_stiffness_times_offset_from_mid_stroke(cfg):
    """F_load = F + K (x - L/2)."""
    kst = 5e4
    c = cfg.replace(effects={"position_dependent_load": {"stiffness": kst}})
    out = []
    for x in (0.03, 0.12):
        P = parameter_vector(c, load=4000.0)
        y = initial_state(c, P, x)
        _, aux, _ = _rhs(c, y, load=4000.0)
        out.append(aux[A_LOAD])
    assert out[1] - out[0] == pytest.approx(kst * 0.09, rel=1e-12)
    assert out[0] == pytest.approx(4000.0 + kst * (0.03 - 0.08), rel=1e-12)


def test_linkage_compliance_couples_the_bodies_through_its_spring(cfg):
    """Stretch the link by 1 mm: body 1 (mass M/2) gains K * 1 mm / (M/2) of acceleration."""
    kst = 2e6
    c = cfg.replace(effects={"linkage_compliance": {"stiffness": kst, "damping": 0.0}})
    P = parameter_vector(c, load=0.0)
    y = initial_state(c, P, 0.08, (4.5e5, 4.5e5))
    dy0, _, _ = _rhs(c, y)
    y2 = y.copy()
    y2[S_X2] = y[S_X2] + 1e-3  # 1 mm beyond the rest deflection initial_state gives the link
    dy1, _, _ = _rhs(c, y2)
    m1 = 0.5 * cfg.p("cylinder.moving_mass")
    assert dy1[S_V] - dy0[S_V] == pytest.approx(kst * 1e-3 / m1, rel=1e-6)

"""Plant B (seed 001): configuration, friction eq. (8), flow laws eqs. (5)-(7), the flow-law claim."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from compliance.model.config import load_plant
from compliance.errors import InputError
from compliance.model.vector_slots import A_QA, N_AUX, N_STATES, P_FJ, P_FRM, P_KV1, P_KV2, P_VD, S_PA, S_PB, S_V
from compliance.physics.friction import piecewise_stribeck_friction
from compliance.physics.valve_flow import bobrow_mass_flow, iso6358_mass_flow, power_law_mass_flow, sanville_mass_flow
from compliance.model.assembly import plant_rhs
from compliance.model.plant_vector import load_curve_arrays, parameter_vector
from compliance.model.rest_state import initial_state
from compliance.model import axis_design as design
from compliance.characterise import flow_rating
from compliance.characterise.flow_trend import flow_claim

ROOT = Path(__file__).resolve().parents[2]
GAMMA, R, T = 1.4, 287.0, 293.15


@pytest.fixture(scope="module")
def cfg():
    return load_plant(ROOT / "models" / "plant-b.toml")


# --------------------------------------------------------------------------- configuration
def test_copies_identical():
    assert (ROOT / "models" / "plant-b.toml").read_bytes() == (ROOT / "compliance" / "data" / "plants" / "plant-b.toml").read_bytes()
    req = ROOT / "requirements" / "tracking-robot.toml"
    assert req.read_bytes() == (ROOT / "compliance" / "data" / "requirements" / "tracking-robot.toml").read_bytes()


def test_reference_values(cfg):
    assert cfg.options["cylinder.arrangement"] == "single"
    assert cfg.options["friction.model"] == "piecewise_stribeck"
    assert cfg.p("cylinder.piston_diameter") == pytest.approx(0.032)
    assert cfg.p("cylinder.rod_diameter") == pytest.approx(0.012)
    assert cfg.p("cylinder.stroke") == pytest.approx(0.3)
    assert cfg.p("cylinder.moving_mass") == pytest.approx(2.5)
    assert cfg.p("cylinder.dead_volume") == pytest.approx(2e-5)
    assert cfg.p("air.supply_pressure") == pytest.approx(6e5 + 1.013e5)  # 6 bar gauge over the file's atmosphere
    assert cfg.p("valve.centre_voltage") == pytest.approx(5.0)
    assert cfg.p("valve.centre_voltage") + cfg.p("valve.command_limit") == pytest.approx(10.0)  # 0-10 V valve
    assert cfg.p("friction.breakaway_force") == pytest.approx(25.0)
    assert cfg.p("friction.low_speed_coefficient") == pytest.approx(800.0)
    assert cfg.p("friction.critical_velocity") == pytest.approx(0.01)
    assert cfg.p("friction.high_speed_coefficient") == pytest.approx(60.0)
    assert load_plant("plant-b").digest == cfg.digest  # the reference name resolves to the same bytes


def test_every_value_in_the_file_says_where_it_comes_from():
    data = tomllib.loads((ROOT / "models" / "plant-b.toml").read_text())
    for section, table in data.items():
        if not isinstance(table, dict):
            continue
        for key, entry in table.items():
            if isinstance(entry, dict):
                assert entry.get("source") in ("paper", "assumed", "derived"), f"{section}.{key} has no source"


def test_rating_coefficients_in_file_match_their_derivation(cfg):
    c = flow_rating.rating_coefficients(700.0, cfg.p("air.atmospheric_pressure"), cfg.p("air.supply_pressure"))
    # written with 5 significant digits
    for key in ("sonic_conductance", "effective_area", "bobrow_coefficient", "power_law_c1", "power_law_c2"):
        assert cfg.p(f"valve.{key}") == pytest.approx(c[key], rel=1e-4), key


def test_every_law_passes_through_the_rating(cfg):
    c = flow_rating.rating_coefficients(700.0, cfg.p("air.atmospheric_pressure"), cfg.p("air.supply_pressure"))
    q700 = 700e-3 / 60.0 * 1.204  # 700 NL/min of ANR air [kg/s]
    for law, q in flow_rating.check_rating(c).items():
        assert q == pytest.approx(q700, rel=1e-12), law


def test_pid_gains_in_file_match_their_design(cfg):
    kp, ki, kd = design.pid_gains(design.axis_model(cfg))
    assert cfg.p("controller.kp") == pytest.approx(kp, rel=0.01)  # written to 2-3 digits
    assert cfg.p("controller.ki") == pytest.approx(ki, rel=0.01)
    assert cfg.p("controller.kd") == pytest.approx(kd, abs=1e-12)


def test_bad_friction_parameters_raise(cfg):
    bad = cfg.replace(params={"friction.low_speed_coefficient": 3000.0})  # F_j - k_v1 v_d = 25 - 30 < 0
    with pytest.raises(InputError, match="eq. \\(8\\)"):
        parameter_vector(bad)


def test_plant_a_unchanged_by_the_new_entries():
    a = load_plant(ROOT / "models" / "plant-a.toml")
    P = parameter_vector(a)
    assert a.options["friction.model"] == "lugre" and P[P_FRM] == 0.0
    assert P[P_FJ] == 0.0 and P[P_KV1] == 0.0 and P[P_KV2] == 0.0 and P[P_VD] == pytest.approx(0.01)  # defaults
    assert a.options["controller.type"] == "pid"


# --------------------------------------------------------------------------- friction, seed 001 eq. (8)
def _sliding(v):
    """eq. (8) friction while sliding (outside the 0.5 mm/s stick band, applied force irrelevant)."""
    return piecewise_stribeck_friction(v, 0.0, 25.0, 800.0, 0.01, 60.0, 5e-4)


def test_piecewise_stribeck_hand_values():
    assert _sliding(0.005) == pytest.approx(25.0 - 800.0 * 0.005)  # 21 N, falling branch
    assert _sliding(0.02) == pytest.approx(25.0 - 8.0 + 60.0 * 0.01)  # 17.6 N, rising branch
    assert _sliding(-0.02) == pytest.approx(-17.6)  # opposes the motion
    assert _sliding(0.01 - 1e-12) == pytest.approx(_sliding(0.01 + 1e-12), abs=1e-8)  # continuous at v_d


def test_stick_band_balances_up_to_breakaway():
    args = (25.0, 800.0, 0.01, 60.0, 5e-4)
    assert piecewise_stribeck_friction(0.0, 10.0, *args) == 10.0  # sticks: friction = applied
    assert piecewise_stribeck_friction(0.0, -30.0, *args) == -25.0  # breaks away at F_j
    assert piecewise_stribeck_friction(0.002, 0.0, *args) == pytest.approx(25.0 - 1.6)  # sliding


def _net_force_state(cfg, P, force):
    """State at rest at mid-stroke with a net pneumatic force ``force`` [N] on the piston."""
    y = initial_state(cfg, P, 0.15)
    a1, a2 = cfg.piston_area, cfg.rod_side_area
    y[S_PA] += force / a1  # rod-side pressure unchanged: the extra force is all on side A
    return y


@pytest.mark.parametrize("force, acc", [(20.0, 0.0), (-20.0, 0.0), (30.0, (30.0 - 25.0) / 2.5), (-40.0, (-40.0 + 25.0) / 2.5)])
def test_plant_rhs_sticks_below_breakaway(cfg, force, acc):
    P = parameter_vector(cfg)
    y = _net_force_state(cfg, P, force)
    dy, aux = np.zeros(N_STATES), np.zeros(N_AUX)
    lx, ly = load_curve_arrays(cfg)
    plant_rhs(y, P, cfg.p("valve.centre_voltage"), lx, ly, dy, aux)
    assert dy[S_V] == pytest.approx(acc, abs=1e-9)  # eq. (9) with eq. (8) friction at rest


# --------------------------------------------------------------------------- flow laws at hand-computed points
def test_sanville_choked_and_subsonic():
    area, pu = 1e-5, 7e5
    # choked (p/p_s = 0.3 < C_t = (2/2.4)^3.5 = 0.528): q = A/sqrt(T) p_s sqrt(k/R (2/(k+1))^((k+1)/(k-1)))
    q_choked = area / math.sqrt(T) * pu * math.sqrt(1.4 / 287.0 * (2.0 / 2.4) ** 6.0)
    assert sanville_mass_flow(area, pu, 0.3 * pu, T, GAMMA, R) == pytest.approx(q_choked, rel=1e-12)
    assert q_choked == pytest.approx(1.6525e-2, rel=1e-4)  # 1e-5 * 7e5 / 17.1216 * 0.040420
    # subsonic, p/p_s = 0.8: q = A/sqrt(T) sqrt(k/R 2/(k-1)) p_s sqrt(r^(2/k) - r^((k+1)/k))
    r = 0.8
    q_sub = area / math.sqrt(T) * math.sqrt(1.4 / 287.0 * 2.0 / 0.4) * pu * math.sqrt(r ** (2 / 1.4) - r ** (2.4 / 1.4))
    assert sanville_mass_flow(area, pu, r * pu, T, GAMMA, R) == pytest.approx(q_sub, rel=1e-12)
    assert sanville_mass_flow(area, r * pu, pu, T, GAMMA, R) == pytest.approx(-q_sub, rel=1e-12)  # reverse flow
    ct = (2.0 / 2.4) ** 3.5
    at_ct = sanville_mass_flow(area, pu, ct * pu * (1 + 1e-9), T, GAMMA, R)
    assert at_ct == pytest.approx(q_choked, rel=1e-6)  # the two branches meet at C_t


def test_bobrow_and_power_law():
    assert bobrow_mass_flow(4e-5, 1.0, 7e5, 6e5) == pytest.approx(4e-5 * math.sqrt(1e5), rel=1e-12)
    assert bobrow_mass_flow(4e-5, 0.5, 6e5, 7e5) == pytest.approx(-0.5 * 4e-5 * math.sqrt(1e5), rel=1e-12)
    dp = 3e5
    q = 7e-4 * dp**0.25 + 1.5e-8 * dp
    assert power_law_mass_flow(7e-4, 1.5e-8, 0.25, 1.0, 7e5, 4e5) == pytest.approx(q, rel=1e-12)
    assert power_law_mass_flow(7e-4, 1.5e-8, 0.25, 0.5, 4e5, 7e5) == pytest.approx(-0.5 * q, rel=1e-12)


def test_iso6358_choked_and_subsonic():
    c, rho0 = 2.3228e-8, 1.204
    assert iso6358_mass_flow(1.0, c, 7e5, 2e5, T, 0.528, rho0, T) == pytest.approx(c * 7e5 * rho0, rel=1e-12)
    a = 0.8
    w = math.sqrt(1.0 - ((a - 0.528) / (1.0 - 0.528)) ** 2)
    assert iso6358_mass_flow(1.0, c, 7e5, a * 7e5, T, 0.528, rho0, T) == pytest.approx(c * 7e5 * rho0 * w, rel=1e-12)


@pytest.mark.parametrize("law", ["iso6358", "sanville", "bobrow", "power_law"])
def test_every_flow_law_drives_the_cylinder(cfg, law):
    # full opening towards +x from mid-stroke: chamber A fills, the piston accelerates forward
    c = cfg.replace(options={"valve.flow_law": law})
    P = parameter_vector(c)
    y = initial_state(c, P, 0.15)
    dy, aux = np.zeros(N_STATES), np.zeros(N_AUX)
    lx, ly = load_curve_arrays(c)
    plant_rhs(y, P, 10.0, lx, ly, dy, aux)
    assert dy[S_PA] > 0 and dy[S_PB] < 0
    # the supply flow into A is the law's own value at (p_s, p_A), fully open
    q = aux[A_QA]  # net mass flow into A, all from the supply at full opening
    assert q > 0.3 * 700e-3 / 60 * 1.204  # at least the order of the rating at these pressure differences


# --------------------------------------------------------------------------- seed 001 claim (1)
def test_power_law_fits_the_flow_trend_where_sanville_and_bobrow_misfit(cfg):
    claim = flow_claim(cfg.p("air.supply_pressure"), cfg.p("air.atmospheric_pressure"))
    rel = claim.relative_rms
    # the trend is the detailed valve's flow: the Savitzky-Golay derivative of a 200 Pa-noise record
    truth_err = np.sqrt(np.mean((claim.trend - claim.true_flow) ** 2)) / np.max(claim.trend)
    assert truth_err < 0.02
    assert rel["power-0.25"] < rel["sanville"] and rel["power-0.25"] < rel["bobrow"]
    # the misfits are systematic (shape), not noise: each is several times the trend's own error
    assert min(rel["sanville"], rel["bobrow"]) > 3.0 * truth_err

"""position_dependent_friction: each cylinder's static and Coulomb friction scale by 1 + a (x - L/2) at its own piston.

Checked on the right-hand side itself at single states (sliding level, stick band, two bodies),
at rest (the LuGre bristles hold what the scaled static friction holds), and in the linear model
(which keeps only the viscous friction, so the effect leaves it unchanged).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from compliance.effects.linkage_compliance import S_V2, S_X2
from compliance.effects.position_dependent_friction import MIN_FACTOR, squeeze_factor
from compliance.linear.trim import linearise_plant, trim
from compliance.model.assembly import plant_rhs
from compliance.model.config import load_plant
from compliance.model.plant_vector import load_curve_arrays, parameter_vector
from compliance.model.rest_state import initial_state
from compliance.model.vector_slots import A_FRIC, N_AUX, N_STATES, S_V, S_Z1
from compliance.simulation import Scenario
from compliance.plants import simulate
from compliance.simulation.profiles import steps

GRADIENT = -10.0  # 1/m, the declared bound: factor 1.6 at x = 20 mm, 0.4 at x = 140 mm of the 160 mm stroke
MID = 0.08  # m, mid-stroke of plant A


@pytest.fixture(scope="module")
def cfg():
    return load_plant("plant-a")


def _rhs(c, y):
    P = parameter_vector(c, load=0.0)
    lx, ly = load_curve_arrays(c)
    dy, aux = np.zeros(N_STATES), np.zeros(N_AUX)
    plant_rhs(y, P, 0.0, lx, ly, dy, aux)
    return dy, aux


def _on(c, gradient=GRADIENT, **more):
    return c.replace(effects={"position_dependent_friction": {"position_gradient": gradient}, **more})


def test_squeeze_factor_is_linear_about_mid_stroke_and_floored():
    assert squeeze_factor(GRADIENT, 0.0) == 1.0
    assert squeeze_factor(GRADIENT, 0.02 - MID) == pytest.approx(1.6, rel=1e-15)
    assert squeeze_factor(GRADIENT, 0.14 - MID) == pytest.approx(0.4, rel=1e-15)
    assert squeeze_factor(-40.0, 0.08) == MIN_FACTOR  # 1 - 3.2 would reverse the friction: floored


def test_sliding_friction_levels_scale_at_the_piston_position_viscous_part_does_not(cfg):
    """Variable-viscous map (no bristle state): F = n (g(v) s(x) + b v), two cylinders."""
    c0 = cfg.replace(options={"friction.model": "variable_viscous"})
    b, v = cfg.p("friction.viscous_coefficient"), 0.02
    fc, fs, vs = cfg.p("friction.coulomb_force"), cfg.p("friction.static_force"), cfg.p("friction.stribeck_velocity")
    g0 = fc + (fs - fc) * math.exp(-v / vs)
    for x in (0.02, 0.08, 0.14):
        y = initial_state(c0, parameter_vector(c0, load=0.0), x, (5e5, 4e5))
        y[S_V] = v
        _, aux = _rhs(_on(c0), y)
        assert aux[A_FRIC] == pytest.approx(2 * (g0 * (1 + GRADIENT * (x - MID)) + b * v), rel=1e-12)


def test_the_stick_band_follows_the_position(cfg):
    """A net force 1.2 x the static friction of the pair: the base model slides, with the effect the
    piston sticks at 20 mm (band x 1.6) and slides harder at 140 mm (band x 0.4)."""
    c0 = cfg.replace(options={"friction.model": "variable_viscous"})
    net = 1.2 * 2 * cfg.p("friction.static_force")  # N
    dp = net / (cfg.piston_area + cfg.rod_side_area)  # tandem: (p_A - p_B)(A_cap + A_rod) = F
    acc = {}
    for name, c in (("off", c0), ("on", _on(c0))):
        for x in (0.02, 0.14):
            y = initial_state(c0, parameter_vector(c0, load=0.0), x, (4.5e5 + 0.5 * dp, 4.5e5 - 0.5 * dp))
            acc[name, x] = _rhs(c, y)[0][S_V]
    assert acc["off", 0.02] > 0.0 and acc["off", 0.14] > 0.0
    assert acc["on", 0.02] == 0.0  # stuck: |F| <= 2 x 1.6 F_S
    assert acc["on", 0.14] > acc["off", 0.14]  # 0.4 F_S per cylinder resists less than F_S


def test_with_a_compliant_linkage_each_cylinder_has_the_friction_of_its_own_position(cfg):
    c0 = cfg.replace(options={"friction.model": "variable_viscous"})
    c = _on(c0, linkage_compliance={"stiffness": 2e6, "damping": 0.0})
    b, v = cfg.p("friction.viscous_coefficient"), 0.02
    fc, fs, vs = cfg.p("friction.coulomb_force"), cfg.p("friction.static_force"), cfg.p("friction.stribeck_velocity")
    g0 = fc + (fs - fc) * math.exp(-v / vs)
    y = initial_state(c, parameter_vector(c, load=0.0), 0.05, (5e5, 4e5))
    y[S_X2], y[S_V], y[S_V2] = 0.07, v, v
    _, aux = _rhs(c, y)
    expected = sum(g0 * (1 + GRADIENT * (x - MID)) + b * v for x in (0.05, 0.07))
    assert aux[A_FRIC] == pytest.approx(expected, rel=1e-12)


def test_with_pressure_dependent_friction_the_factors_multiply(cfg):
    c0 = cfg.replace(options={"friction.model": "variable_viscous"})
    k, x, pa, pb = 1e-6, 0.03, 6e5, 4e5
    b, v = cfg.p("friction.viscous_coefficient"), 0.02
    y = initial_state(c0, parameter_vector(c0, load=0.0), x, (pa, pb))
    y[S_V] = v
    _, base = _rhs(c0, y)
    _, both = _rhs(_on(c0, pressure_dependent_friction={"coefficient": k}), y)
    gauge = 0.5 * (pa + pb) - cfg.p("air.atmospheric_pressure")
    g0 = base[A_FRIC] / 2 - b * v
    assert both[A_FRIC] == pytest.approx(2 * (g0 * (1 + k * gauge) * (1 + GRADIENT * (x - MID)) + b * v), rel=1e-12)


def test_at_rest_the_bristles_hold_what_the_scaled_static_friction_holds(cfg):
    """LuGre: the rest state deflects the bristles by F/(n sigma0) up to g(0) s(x)/sigma0 (Canudas de Wit 1995)."""
    net = 1.2 * 2 * cfg.p("friction.static_force")
    dp = net / (cfg.piston_area + cfg.rod_side_area)
    sig0, fs = cfg.p("friction.bristle_stiffness"), cfg.p("friction.static_force")
    pressures = (4.5e5 + 0.5 * dp, 4.5e5 - 0.5 * dp)
    y_off = initial_state(cfg, parameter_vector(cfg, load=0.0), 0.02, pressures)
    y_on = initial_state(_on(cfg), parameter_vector(_on(cfg), load=0.0), 0.02, pressures)
    assert y_off[S_Z1] == pytest.approx(fs / sig0, rel=1e-12)  # clipped: the base friction cannot hold it
    assert y_on[S_Z1] == pytest.approx(net / 2 / sig0, rel=1e-6)  # held: 1.2 F_S < 1.6 F_S


def test_the_linear_model_keeps_only_viscous_friction_so_the_effect_leaves_it_unchanged(cfg):
    ops = [trim(c, 0.04, 4000.0) for c in (cfg, _on(cfg))]
    (a0, b0, *_), (a1, b1, *_) = (linearise_plant(op, c) for op, c in zip(ops, (cfg, _on(cfg))))
    assert np.array_equal(a0, a1) and np.array_equal(b0, b1)


def test_zero_gradient_changes_nothing_and_a_gradient_changes_a_step(cfg):
    sc = Scenario(duration=1.5, initial_position=0.04, reference=steps("2%@0.2s", 0.04, 0.16), load=5000.0)
    base = simulate(cfg, sc).position_true.to_numpy()
    assert np.array_equal(base, simulate(_on(cfg, 0.0), sc).position_true.to_numpy())
    assert not np.array_equal(base, simulate(_on(cfg), sc).position_true.to_numpy())

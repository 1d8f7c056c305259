"""Pressure-dependent friction: the seal friction levels rise with the pressure behind the seals."""

from __future__ import annotations

from numba import njit

from compliance.effects.base import Effect
from compliance.effects.param import Param

# slots in the compiled core (tests/effects/test_effect_slots.py checks them against the layout)
P_PF_ON = 67
P_PF_COEF = 68


@njit(cache=True, error_model="numpy", inline="always")
def pressure_friction_factor(coefficient, mean_chamber_pressure, atmosphere):
    """Factor on the seal friction levels from the chamber pressure, 1 + k_p*(p_mean - p_atm) [-].

    A lip seal's friction is the contact pressure times the contact area, and the pressure
    behind the lip adds to the contact pressure, so both friction levels scale with it
    (Belforte et al. 2003, "Pneumatic cylinder seal friction"); scaling F_C and F_S alike keeps
    the Stribeck shape. ``coefficient`` is the relative rise per Pa of mean gauge pressure [1/Pa].
    """
    return 1.0 + coefficient * max(mean_chamber_pressure - atmosphere, 0.0)


@njit(cache=True, error_model="numpy", inline="always")
def friction_level(P, position, mean_pressure, atmosphere, stroke, factor):
    """Hook ``friction_level``: ``factor`` times the pressure factor (pressures [Pa abs])."""
    return factor * pressure_friction_factor(P[P_PF_COEF], mean_pressure, atmosphere)  # Belforte et al. 2003


EFFECT = Effect(
    name="pressure_dependent_friction",
    meaning="seal friction rises with the pressure behind the seals: F_C and F_S scale by 1 + k (mean gauge pressure)",
    short="pf",
    slot=P_PF_ON,
    # a lip seal's friction is its contact pressure times area; the pressure behind the lip adds to the
    # contact pressure, so both levels scale with it (Belforte et al. 2003) and the Stribeck shape is kept;
    # 5e-6 /Pa (0.5 per bar) nearly triples the friction at the mean gauge pressure of an 8 bar supply
    params=(Param("coefficient", "1/Pa", "relative rise of Coulomb and static friction per Pa of mean chamber gauge pressure",
                  5e-7, (0.0, 5e-6), slot="coef", aliases=("kp_fric",)),),
    states=(),
    signature="larger stick-slip and steady error at high chamber pressures; breakaway needs more pressure difference",
    signals=("position", "valve_command", "pressure_a", "pressure_b"),
    explanation="the seal friction grows with the chamber pressure (friction levels x (1 + k p_gauge), k = {v})",
    fit_grid={"coefficient": (2e-7, 6e-7, 1.5e-6, 3e-6)},
    draw={"coefficient": (6e-7, 3e-6, True)},
    terms={"friction_level": friction_level},
)

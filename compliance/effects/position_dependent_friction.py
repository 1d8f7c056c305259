"""Position-dependent friction: the seal friction level changes along the stroke of the servo cylinder.

A seal's friction follows its contact force, which follows its squeeze; a bore whose diameter
varies along the stroke (wear, a slight taper or ovality) changes the squeeze and so the
friction at each position (Parker O-Ring Handbook ORD 5700, 2021, sec. 5, running friction).
The seal bench data (Zillen, TU Delft: friction of one seal stroked at 1-7 bar) shows its
friction changing with position at every pressure; the bench diagnosis declares the same
physics, expanded to second order about the runs' median position, as its own effect
``friction_along_stroke`` (``compliance.diagnosis.friction_bench.position``). In the servo both Stribeck levels (and the
breakaway force of the piecewise model) of each cylinder are scaled by the factor at its own
piston position, taken linear about mid-stroke (our choice; the bench adds a curvature term
about the median of its runs) and never below ``MIN_FACTOR``.
"""

from __future__ import annotations

from numba import njit

from compliance.effects.base import Effect
from compliance.effects.param import Param

# slots in the compiled core (tests/effects/test_effect_slots.py checks them against the layout)
P_XF_ON = 96
P_XF_GRAD = 97

MIN_FACTOR = 0.05  # the factor is floored here: a friction level never changes sign along the bore


@njit(cache=True, error_model="numpy", inline="always")
def squeeze_factor(gradient, offset):
    """Relative friction level max(1 + a*(x - x_mid), MIN_FACTOR) [-] at ``offset`` = x - x_mid [m], ``gradient`` a [1/m].

    Friction proportional to the seal's squeeze (Parker ORD 5700, 2021, sec. 5); linear in position: our choice.
    """
    return max(1.0 + gradient * offset, MIN_FACTOR)


@njit(cache=True, error_model="numpy", inline="always")
def friction_level(P, position, mean_pressure, atmosphere, stroke, factor):
    """Hook ``friction_level``: ``factor`` times the squeeze factor at the piston ``position`` [m] (stroke [m])."""
    return factor * squeeze_factor(P[P_XF_GRAD], position - 0.5 * stroke)  # about mid-stroke


EFFECT = Effect(
    name="position_dependent_friction",
    meaning="the seal's friction level changes along the stroke (squeeze varying with the bore)",
    short="xf",
    slot=P_XF_ON,
    # +-10 /m moves the level by +-0.8 at the ends of a 0.16 m stroke: the bench's +-40 /m over its 40 mm travel
    params=(Param("position_gradient", "1/m", "relative change of both friction levels per metre of travel at mid-stroke",
                  0.0, (-10.0, 10.0), slot="grad"),),
    states=(),
    signature="steady error and stick-slip differ along the stroke; the pressure difference at breakaway changes with position",
    signals=("position", "valve_command", "pressure_a", "pressure_b"),
    explanation="the seal friction changes along the stroke (friction levels x (1 + a (x - mid-stroke)), a = {v})",
    fit_grid={"position_gradient": (-6.0, -2.0, 2.0, 6.0)},
    draw={"position_gradient": (2.0, 8.0, False)},
    draw_signed=True,
    terms={"friction_level": friction_level},
)

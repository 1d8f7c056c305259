"""Declared bench effects of the chamber pressure beyond the linear law: a friction rise that is not
linear in the pressure, and a pressure force that is not linear in the logged pressure.

``nonlinear_pressure_friction``: the pressure-energised part of the seal's contact force, and so of
its friction, is not proportional to the pressure. The running friction of an elastomer seal is
the sum of a squeeze part and a fluid-pressure part, F = f_c L_p + f_h A_p, with f_h a non-linear
function of the pressure read from a chart (Parker O-Ring Handbook ORD 5700, 2021, section 5,
"Friction"); the contact band of a seal widens as the pressure presses it against the bore, so the
rise can be faster than linear (an X-ring's lobes flattening) or slower (an O-ring filling its
groove). A power law about the seal's median run pressure p_r carries both:

    F_C(p) = F_C0 + k_p p_r (p_g / p_r)^n,   F_S(p) = F_S0 + k_p p_r (p_g / p_r)^n,

n = 1 is the linear law (``pressure_dependent_friction``), so k_p keeps its meaning at p_r. The
power-law form of f_h and the reference p_r are our choices.

``pressure_force_curvature``: the bench measures friction as F - p_g A (Zillen et al. eq. 3) with
one piston area A. A pressure force that is not linear in the logged pressure -- a pressure
transducer with a second-order calibration error, or an effective piston area that changes with
the pressure (a printed barrel dilating, the seal's line of contact moving in its groove) -- leaves
a direction-independent force c2 p_g^2 besides the area error c1 p_g: the bias becomes

    F_bias = c0 + c1 p_g + c2 p_g^2.

It is instrumentation of the bench, not friction: it shows up as a force offset that differs from
run to run, smoothly with the run's pressure (a second-order calibration term: our choice).
"""

from __future__ import annotations

import numpy as np

from compliance.effects.param import Param
from compliance.diagnosis.friction_bench.position import BenchEffect

NONLINEAR_PRESSURE = BenchEffect(
    name="nonlinear_pressure_friction",
    meaning="the seal's friction rises with the chamber pressure along a power law, not a straight line",
    params=(Param("pressure_exponent", "", "exponent n of the pressure rise of both friction levels (1: linear)",
                  1.0, (0.2, 6.0), log_scale=True),),
    equations="F_C,S(p) = F_C0,S0 + k_p p_r (p_g / p_r)^n",
    source="fluid-pressure friction f_h A_p, f_h non-linear in the pressure (Parker O-Ring Handbook ORD 5700, 2021); "
           "power-law form and p_r: our choice",
)

PRESSURE_FORCE = BenchEffect(
    name="pressure_force_curvature",
    meaning=("a direction-independent force that grows with the square of the chamber pressure (pressure transducer "
             "non-linearity or a piston area that changes with pressure: instrumentation, not friction)"),
    params=(Param("bias_per_pressure_squared", "N/Pa^2", "direction-independent force per Pa^2 of chamber gauge pressure, c2",
                  0.0, (-2e-10, 2e-10)),),
    equations="F_bias = c0 + c1 p_g + c2 p_g^2",
    source="friction = F - p_g A (Zillen et al. eq. 3) with a second-order pressure-force term: our choice",
)


def reference_pressure(runs) -> float:
    """p_r [Pa]: the median of the runs' mean gauge pressures (fixed, not fitted); at least 1 kPa."""
    return max(float(np.median([r.pressure for r in runs])), 1e3)


def pressure_rise(pressure_gauge, coefficient: float, exponent: float = 1.0, reference: float = 1.0):
    """Rise of both friction levels with the gauge pressure [N]: k_p p_g (n = 1) or k_p p_r (p_g / p_r)^n."""
    p = np.asarray(pressure_gauge, dtype=float)
    if exponent == 1.0:
        return coefficient * p
    return coefficient * reference * np.power(np.maximum(p, 0.0) / reference, exponent)


__all__ = ["NONLINEAR_PRESSURE", "PRESSURE_FORCE", "reference_pressure", "pressure_rise"]

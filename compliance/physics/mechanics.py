"""Piston forces, cylinder geometry and end stops."""

from __future__ import annotations

from numba import njit


@njit(cache=True, error_model="numpy", inline="always")
def single_volumes(x, stroke, dead_volume, area_cap, area_rod):
    """Chamber volumes of one double-acting cylinder [m^3] (seed 001 fig. 1: V_a = V0 + A1*x, V_b = V0 + A2*(L - x))."""
    return dead_volume + area_cap * x, dead_volume + area_rod * (stroke - x)


@njit(cache=True, error_model="numpy", inline="always")
def single_force(p_a, p_b, area_cap, area_rod, p_atm):
    """Net pneumatic force of one single-rod cylinder [N] (seed 001 eq. 9, with the rod side vented to atmosphere)."""
    return p_a * area_cap - p_b * area_rod - p_atm * (area_cap - area_rod)


@njit(cache=True, error_model="numpy", inline="always")
def end_stop_force(x, v, stroke, stiffness, damping):
    """Contact force of the end stops at x = 0 and x = L [N] (stiff spring-damper, one-sided).

    Positive pushes towards the stroke; zero inside it. The damping only pushes, never pulls.
    """
    if x < 0.0:
        f = -stiffness * x - damping * v
        return f if f > 0.0 else 0.0
    if x > stroke:
        f = -stiffness * (x - stroke) - damping * v
        return f if f < 0.0 else 0.0
    return 0.0


@njit(cache=True, error_model="numpy", inline="always")
def interp_curve(x, xs, ys):
    """Piecewise-linear interpolation held flat outside the samples (load curve over the stroke)."""
    n = xs.shape[0]
    if x <= xs[0]:
        return ys[0]
    if x >= xs[n - 1]:
        return ys[n - 1]
    lo = 0
    hi = n - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if xs[mid] <= x:
            lo = mid
        else:
            hi = mid
    w = (x - xs[lo]) / (xs[hi] - xs[lo])
    return ys[lo] + w * (ys[hi] - ys[lo])

"""Discrete steps of the reduced-order observers of seed 001 eqs. (10)-(11) (compiled)."""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True, error_model="numpy", inline="always")
def gauge_pressure_input(p_a, p_b, area_ratio, atmosphere):
    """Input u_p = p_A - (A2/A1) p_B of seed 001 eq. (11), in gauge pressures [Pa].

    seed 001 eq. (9) writes (p_a A1 - p_b A2) - F_f = M a; with absolute chamber pressures the
    rod side's atmospheric force p_atm (A1 - A2) enters, so gauge pressures make eq. (9) exact.
    """
    return (p_a - atmosphere) - area_ratio * (p_b - atmosphere)


@njit(cache=True, error_model="numpy", inline="always")
def observer_foh_step(w, pole, drive_start, drive_end, sample_time):
    """Advance w' = pole*w + d(t) over one sample with d linear from ``drive_start`` to ``drive_end``.

    Exact for a drive that is a straight line over the sample (first-order hold): measured
    states move during the sample, and holding them at their start value would bias the
    estimate by about |state gain| * change / (2 |pole|) per sample. The valve command, held
    by the DAC, is constant, which the straight line includes.

    Parameters
    ----------
    w : float
        Observer state at the start of the sample.
    pole : float
        Error pole [1/s] (< 0).
    drive_start, drive_end : float
        Drive at the start and at the end of the sample.
    sample_time : float
        [s].
    """
    lh = pole * sample_time
    e = math.exp(lh)
    g0 = (e - 1.0) / pole  # integral of exp(pole*(h - s)) ds over the sample
    g1 = (e - 1.0 - lh) / (pole * lh)  # integral of exp(pole*(h - s)) * s/h ds
    return e * w + g0 * drive_start + g1 * (drive_end - drive_start)  # seed 001 eqs. (10)-(11), exact FOH

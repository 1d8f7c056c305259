"""Whether a fitted parameter ended on a bound of its fit: then the data did not determine it.

A least-squares fit that stops on a bound reports a standard error near zero (the Jacobian
column vanishes there), which reads as certainty; the diagnosis and friction reports flag such
parameters instead of printing their errors as evidence.
"""

from __future__ import annotations

import math


def at_bound(value, low, high, log: bool = False) -> bool:
    """Whether ``value`` sits on ``low`` or ``high`` (within 0.1 % of the range; log scale for log parameters)."""
    if value is None:
        return False
    if log:
        if value <= 0 or low <= 0:
            return False
        value, low, high = math.log10(value), math.log10(low), math.log10(high)
    tol = 1e-3 * (high - low)
    return value - low <= tol or high - value <= tol


def effect_bound(name: str, value, unit: str = "") -> str | None:
    """"at its fit bound" for a fitted effect parameter ``name`` (``effect.param``) on a bound of its declaration."""
    from compliance.effects import EFFECTS
    from compliance.presentation.numbers import fmt_si

    effect, _, param = str(name or "").partition(".")
    eff = EFFECTS.get(effect)
    if eff is None or not param or value is None:
        return None
    try:
        spec = eff.param(param)
    except (KeyError, ValueError):
        return None
    lo, hi = spec.bounds
    if at_bound(value, lo, hi, bool(getattr(spec, "log_scale", False))):
        edge = lo if abs(value - lo) <= abs(value - hi) else hi
        return f"at its fit bound ({fmt_si(edge, unit or '')}): not determined by the recording"
    return None

"""Does the recording pin the split of a lag, or only its total? A scan along the lumped valley.

A spool or a transducer below the loop's bandwidth shows the loop its total lag (``Effect.lumped``);
its main parameter (spool natural frequency, transducer time constant) and its pure delay trade
along a valley of the fit. After the winner is fitted, its main parameter is moved over
``SPLIT_FACTORS`` of the fitted value while the delay is re-solved to keep the total lag at its
fitted value (the other parameters stay at the fit), and each point is replayed. The values whose
replay is as good an explanation as the fit by the verdict's own rule for indistinguishable
explanations - chi-square within ``AMBIGUOUS_RATIO`` of the fit's, and no signal above
``RESIDUAL_LIMIT`` times its floor or, when the fit itself sits near that limit, above the fit's
worst signal by more than the same ratio in chi-square - form the *split interval* (the connected
run of such values around the fit). When it spans more than a factor
``PINNED_SPAN`` the recording pins the total, not the split, and the diagnosis says so with
the interval instead of presenting the fitted split as measured.

Why this rule and not a statistical interval: the replay's chi-square has wrinkles along the
valley (a stall point or breakaway moves when the lag shifts by a millisecond), measured on the
independent sensor-lag recording at 10-20 % of chi2/N between neighbouring points of one
valley, far above any Gaussian profile threshold (the sandwich standard error of the independent
valve recording's spool frequency is 0.25 % of it); two splits whose chi-squares differ by less than those wrinkles are not told apart
by the recording, which is the same judgement the verdict makes between two explanations.
"""

from __future__ import annotations

import math

import numpy as np

from compliance.effects import EFFECTS
from compliance.diagnosis.select import AMBIGUOUS_RATIO, RESIDUAL_LIMIT

SPLIT_FACTORS = (0.5, 0.6, 0.7, 0.8, 0.9, 1.12, 1.25, 1.5, 2.0)  # main parameter / fitted value
PINNED_SPAN = 1.25  # an interval wider than this factor (max / min) leaves the split undetermined


def _delay_param(effect: str) -> str | None:
    eff = EFFECTS[effect]
    return eff.input_delay or eff.output_delay


def _valley_point(effect: str, vals: dict, main: str, delay: str, value: float, total: float) -> dict | None:
    """The parameters with ``main`` at ``value`` and the delay re-solved to keep the lumped total."""
    lumped = EFFECTS[effect].lumped.of
    p = dict(vals)
    p[main] = value
    p[delay] = 0.0
    g0 = float(lumped(p))
    p[delay] = 1e-3
    slope = (float(lumped(p)) - g0) / 1e-3  # the delay enters the total lag linearly
    if slope <= 0.0:
        return None
    p[delay] = (total - g0) / slope
    return p


def split_scan(ctx, fit, effect: str) -> dict | None:
    """Scan the lumped valley of ``effect`` in the fitted candidate ``fit`` (``fit.FitContext`` ``ctx``).

    Returns
    -------
    dict or None
        ``parameter`` (key of the main parameter), ``fitted``, ``points`` [(value, chi2/N, largest
        normalised RMS)], ``interval`` [low, high] of the values indistinguishable from the fit,
        ``pinned`` (interval narrower than ``PINNED_SPAN``), ``lumped`` (total held) - or None when
        the effect declares no lumped combination with a delay.
    """
    decl = EFFECTS.get(effect)
    delay = _delay_param(effect) if decl is not None else None
    if decl is None or decl.lumped is None or delay is None:
        return None
    idx = {fp.name: i for i, fp in enumerate(fit.params) if fp.kind == "effect" and fp.effect == effect}
    if len(idx) != len(decl.params):
        return None
    main = decl.params[0].name
    vals = {n: fit.values[i] for n, i in idx.items()}
    total = float(decl.lumped.of(vals))
    lo_b, hi_b = fit.params[idx[main]].low, fit.params[idx[main]].high
    d_lo, d_hi = fit.params[idx[delay]].low, fit.params[idx[delay]].high
    m = ctx.model.index.size
    n = ctx.model.size
    best = fit.chi2
    points = [(vals[main], fit.chi2 / n, max(math.sqrt(c / m) for c in fit.chi2_signal.values()))]
    for f in SPLIT_FACTORS:
        value = vals[main] * f
        p = _valley_point(effect, vals, main, delay, value, total) if lo_b <= value <= hi_b else None
        if p is None or not d_lo <= p[delay] <= d_hi:
            continue
        values = list(fit.values)
        values[idx[main]], values[idx[delay]] = value, p[delay]
        vec, sim = ctx.residual(fit.params, values)
        if sim is None:
            continue
        parts = {s: float(np.dot(r, r)) for s, r in ctx.model.split(vec).items()}
        points.append((value, sum(parts.values()) / n, max(math.sqrt(c / m) for c in parts.values())))
    points.sort()
    # no signal may be worse than the limit, or than the fit's own worst signal by the same ratio
    worst_ok = max(RESIDUAL_LIMIT, points[0][2] * math.sqrt(AMBIGUOUS_RATIO))
    ok = [v for v, c, worst in points if c * n <= AMBIGUOUS_RATIO * best and worst <= worst_ok]
    # the interval is the connected run of indistinguishable values around the fit
    values = [v for v, _, _ in points]
    k = values.index(vals[main])
    lo = hi = k
    while lo > 0 and values[lo - 1] in ok:
        lo -= 1
    while hi < len(values) - 1 and values[hi + 1] in ok:
        hi += 1
    interval = [values[lo], values[hi]]
    return {"parameter": f"{effect}.{main}", "fitted": vals[main], "lumped": total, "delay": f"{effect}.{delay}",
            "points": [[v, c, w] for v, c, w in points], "interval": interval,
            "pinned": interval[1] / interval[0] < PINNED_SPAN, "scanned": [values[0], values[-1]]}


def contains(scan: dict | None, value: float) -> bool | None:
    """True when ``value`` lies in the split interval of ``scan`` (None without a scan)."""
    if not scan:
        return None
    return scan["interval"][0] <= value <= scan["interval"][1]


__all__ = ["split_scan", "contains", "SPLIT_FACTORS", "PINNED_SPAN"]

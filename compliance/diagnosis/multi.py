"""Several effects at once: greedy forward selection of effect sets, with re-fitting.

After the best single explanation, the diagnosis searches again on what is left. Every other
effect is screened by switching it on in the current set, unfitted, the set held at its optimum
(``screen_addition``: the added effect at its single-effect optimum, its declared default, and
each value of its main parameter's coarse grid; one worker task per effect). The
``CANDIDATES_PER_ROUND`` effects that lower the chi-square most are each added to the current set
and the whole set is refitted from the screen's best point (``extend_fit``: the first effects
move with the added one). An added effect is kept only when

- it pays for itself by the information criterion (``select.SIGNIFICANCE``),
- it removes at least ``ADD_GAIN`` of the current set's excess chi-square (chi2 - N), and
- it makes no signal worse: no signal's chi-square rises by more than ``NO_WORSE`` to end above
  ``select.RESIDUAL_LIMIT`` times its floor (a third effect that lowers the pooled chi-square by
  trading one signal for another is not physics; a signal that stays at its floor may wobble).

Each effect's own contribution in the final set is the chi-square the set loses when that
effect alone is switched off (the others at their fitted values): one replay per effect.
"""

from __future__ import annotations

from compliance.effects import EFFECTS
from compliance.diagnosis.candidates import effect_candidate
from compliance.diagnosis.fit import FitContext, FitResult, least_squares_fit, scan_points
from compliance.diagnosis.select import RESIDUAL_LIMIT, SIGNIFICANCE

ADD_GAIN = 0.3  # share of the current set's excess chi-square an added effect must remove
NO_WORSE = 1.25  # no signal's chi-square may rise by more than this factor when an effect is added
CANDIDATES_PER_ROUND = 4  # best-screened effects refitted in each round
MAX_EFFECTS = 3  # at most this many effects in one explanation
SET_SIMPLEX_FEV = 8  # simplex evaluations per parameter of a set refit (it starts near the optimum)


def set_name(effects) -> str:
    """Canonical candidate name of an effect set (``a+b``, in the order they were found)."""
    return "+".join(effects)


def set_effects(name: str) -> list[str]:
    """Effect names of a candidate name (``base`` and ``nominal`` dropped)."""
    return [e for e in name.split("+") if e in EFFECTS]


def _start_points(current: FitResult, single: FitResult) -> tuple[tuple, list[list[float]]]:
    """Parameters of ``current`` plus ``single``'s effect, and the starts the screen tries for the added effect.

    The starts: its single-effect optimum, its declared default, and each value of its main
    parameter on its declared coarse grid (other parameters at the single optimum). An effect whose
    single fit was dragged off by a dominant other effect (a leak fitted twice too large under a
    valve lag) has its single optimum and its default both on the wrong side of the value the set
    needs; the grid brackets it, as it does for the single fit.
    """
    added = tuple(fp for fp in single.params if fp.kind == "effect")
    params = tuple(current.params) + added
    opt = [v for fp, v in zip(single.params, single.values) if fp.kind == "effect"]
    starts = [list(current.values) + opt, list(current.values) + [fp.nominal for fp in added]]
    if added:
        main = added[0].name
        for g in effect_candidate(single.name).grid:
            if main in g:
                pt = list(current.values) + [g[main]] + opt[1:]
                if pt not in starts:
                    starts.append(pt)
    return params, starts


def screen_addition(ctx: FitContext, current: FitResult, single: FitResult) -> tuple[str, float, list[float], int]:
    """(effect, chi-square of the current set with ``single``'s effect added, unfitted, at its best start, that start,
    replays run).

    Which effects a round refits, and where each refit starts: an effect whose single fit was
    poor because another effect dominated the recording can still complete the set (a few
    replays per effect over its main parameter's grid, the set held at its optimum, no fit).
    One task of the worker pool per effect.
    """
    params, starts = _start_points(current, single)
    chis = scan_points(ctx, params, starts)
    i = min(range(len(chis)), key=chis.__getitem__)
    return single.name, chis[i], starts[i], len(starts)


def extend_fit(ctx: FitContext, current: FitResult, single: FitResult, start: list[float] | None = None) -> FitResult:
    """Refit ``current`` (an effect set, possibly with base parameters) with ``single``'s effect added.

    The whole set is refitted (the first effects move with the added one), starting at ``start``
    (the screen's best point) or, without it, at the best of ``_start_points``.
    """
    params, starts = _start_points(current, single)
    if start is None:
        chis = scan_points(ctx, params, starts)
        start = starts[min(range(len(chis)), key=chis.__getitem__)]
    names = set_effects(current.name) + set_effects(single.name)
    name = set_name(names) + ("+base" if any(fp.kind == "base" for fp in params) else "")
    return least_squares_fit(ctx, name, params, start, simplex_fev=SET_SIMPLEX_FEV)


def adds_enough(new: FitResult, current: FitResult, n: int, penalty_per_param: float, over_dispersion: float) -> tuple[bool, str]:
    """Whether ``new`` (the set with one more effect) is kept over ``current``; and why (words)."""
    k_added = new.k - current.k
    gain = (current.chi2 - new.chi2) / over_dispersion
    if gain < k_added * penalty_per_param + SIGNIFICANCE:
        return False, f"gains {gain:.0f} in scaled chi-square, less than its information-criterion price"
    excess = max(current.chi2 - n, 0.0)
    if excess <= 0.0 or current.chi2 - new.chi2 < ADD_GAIN * excess:
        share = 0.0 if excess <= 0 else (current.chi2 - new.chi2) / excess
        return False, f"removes {100*share:.0f} % of the remaining excess (needs {100*ADD_GAIN:.0f} %)"
    m = n / max(len(current.chi2_signal), 1)  # residuals per signal
    for s, c in current.chi2_signal.items():
        after = new.chi2_signal.get(s, 0.0)
        if after > NO_WORSE * c and after > RESIDUAL_LIMIT ** 2 * m:
            return False, f"makes the {s} residual worse ({after / max(c, 1e-12):.1f} times its chi-square)"
    return True, f"removes {100*(current.chi2 - new.chi2)/excess:.0f} % of the remaining excess"


def contributions(ctx: FitContext, fit: FitResult) -> dict[str, float]:
    """Effect -> chi-square the fitted set loses when that effect alone is switched off."""
    out = {}
    names = set_effects(fit.name)
    if len(names) < 1:
        return out
    for e in names:
        keep = [(fp, v) for fp, v in zip(fit.params, fit.values) if fp.effect != e]
        vec, _ = ctx.residual(tuple(fp for fp, _ in keep), [v for _, v in keep])
        out[e] = float(vec @ vec) - fit.chi2
    return out


__all__ = ["extend_fit", "adds_enough", "contributions", "set_name", "set_effects", "ADD_GAIN", "NO_WORSE",
           "CANDIDATES_PER_ROUND", "MAX_EFFECTS", "screen_addition"]

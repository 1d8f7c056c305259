"""Several effects at once: greedy forward selection of effect sets, with re-fitting.

After the best single explanation, the diagnosis searches again on what is left. Every other
effect is screened by switching it on in the current set, unfitted, the set held at its optimum
(``screen_addition``: the added effect at its single-effect optimum, its declared default, and
each value of its main parameter's coarse grid; one worker task per effect). The
``CANDIDATES_PER_ROUND`` effects that lower the chi-square most are each added to the current set
and the whole set is refitted from the screen's best point (``extend_fit``: the first effects
move with the added one). An added effect is kept only when

- it pays for itself by the information criterion (``servo.selection.SIGNIFICANCE``),
- it removes at least ``ADD_GAIN`` of the current set's excess chi-square (chi2 - N) outside the one
  ``BURST_WINDOW`` where the current set leaves the most (``burst_trimmed``), when the current set
  leaves more than ``servo.selection.RESIDUAL_LIMIT`` squared times the floor's chi-square there, else of the
  whole excess: one burst that no effect removes must neither hide a real effect nor be the only
  evidence for one, and
- it makes no signal worse: no signal's chi-square rises by more than ``NO_WORSE`` to end above
  ``servo.selection.RESIDUAL_LIMIT`` times its floor (a third effect that lowers the pooled chi-square by
  trading one signal for another is not physics; a signal that stays at its floor may wobble).

Each effect's own contribution in the final set is the chi-square the set loses when that
effect alone is switched off (the others at their fitted values): one replay per effect.
"""

from __future__ import annotations

import numpy as np

from compliance.effects import EFFECTS
from compliance.diagnosis.servo.candidates import effect_candidate
from compliance.diagnosis.servo.fit import FitContext, FitResult, least_squares_fit, scan_points
from compliance.diagnosis.servo.selection import RESIDUAL_LIMIT, SIGNIFICANCE

ADD_GAIN = 0.3  # share of the current set's excess chi-square an added effect must remove
NO_WORSE = 1.25  # no signal's chi-square may rise by more than this factor when an effect is added
CANDIDATES_PER_ROUND = 4  # best-screened effects refitted in each round
MAX_EFFECTS = 3  # at most this many effects in one explanation
# s: a replay's misfit comes in bursts (one stick-slip event the replay makes and the bench did not, or the
# reverse: 1-2 s, fit.HAC_SECONDS); one such burst, which no effect removes, can hold most of a set's excess
BURST_WINDOW = 2.0
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


def burst_trimmed(cur_vec, new_vec, times) -> tuple[float, float]:
    """(share of the current set's excess the new set removes outside the burst window, the current set's
    chi-square per residual there).

    The residuals are cut into ``BURST_WINDOW`` windows of the test; the burst window is the one
    where the current set leaves the largest excess (``times``: the time of each residual).
    """
    cur2, new2 = np.asarray(cur_vec) ** 2, np.asarray(new_vec) ** 2
    w = np.floor((np.asarray(times) - np.min(times)) / BURST_WINDOW).astype(int)
    per = np.bincount(w, weights=cur2 - 1.0)
    out = w != int(np.argmax(per))
    excess = float(np.sum(cur2[out]) - np.count_nonzero(out))
    if excess <= 0.0:
        return 0.0, 1.0
    return float(np.sum(cur2[out] - new2[out])) / excess, float(np.mean(cur2[out]))


def adds_enough(new: FitResult, current: FitResult, n: int, penalty_per_param: float, over_dispersion: float,
                vecs: tuple | None = None) -> tuple[bool, str]:
    """Whether ``new`` (the set with one more effect) is kept over ``current``; and why (words).

    ``vecs``: (current's residuals, new's residuals, time of each residual) for the burst rule.
    """
    k_added = new.k - current.k
    gain = (current.chi2 - new.chi2) / over_dispersion
    if gain < k_added * penalty_per_param + SIGNIFICANCE:
        return False, f"gains {gain:.0f} in scaled chi-square, less than its information-criterion price"
    excess = max(current.chi2 - n, 0.0)
    share = 0.0 if excess <= 0 else (current.chi2 - new.chi2) / excess
    words = f"removes {100*share:.0f} % of the remaining excess"
    trimmed, level = burst_trimmed(*vecs) if vecs is not None else (share, 1.0)
    if level > RESIDUAL_LIMIT ** 2:  # excess left outside the burst: judge there (both ways)
        share = trimmed
        words += f", {100*trimmed:.0f} % outside its largest {BURST_WINDOW:g} s burst"
    if share < ADD_GAIN:
        return False, f"{words} (needs {100*ADD_GAIN:.0f} %)"
    m = n / max(len(current.chi2_signal), 1)  # residuals per signal
    for s, c in current.chi2_signal.items():
        after = new.chi2_signal.get(s, 0.0)
        if after > NO_WORSE * c and after > RESIDUAL_LIMIT ** 2 * m:
            return False, f"makes the {s} residual worse ({after / max(c, 1e-12):.1f} times its chi-square)"
    return True, words


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
           "CANDIDATES_PER_ROUND", "MAX_EFFECTS", "screen_addition", "burst_trimmed", "BURST_WINDOW"]

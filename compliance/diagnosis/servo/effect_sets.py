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

Once the forward search stops, each effect of the set must still earn its place (``prune``,
stepwise backward elimination after the forward steps, Efroymson 1960): an effect found early can be
made redundant by the ones added after it. Every effect is removed in turn and the rest refitted
with the recording's best instrumentation finding on top (a transducer gain, a channel delay:
``instrument_candidates``), so a physical effect stays only when it beats the instrumentation
explanation of the same misfit (``select.beats``); a removed effect's place may go to the finding.

Each effect's own contribution in the final set is the chi-square the set loses when that
effect alone is switched off (the others at their fitted values): one replay per effect.
"""

from __future__ import annotations

import numpy as np

from compliance.diagnosis.servo.candidates import effect_candidate
from compliance.diagnosis.servo.fit import FitContext, FitResult, least_squares_fit, scan_points
from compliance.diagnosis.servo.instrument_candidates import KIND as INSTRUMENT
from compliance.diagnosis.servo.selection import RESIDUAL_LIMIT, SIGNIFICANCE, beats, score_all
from compliance.diagnosis.verdicts.candidate_set import BASE, CandidateSet, is_instrument

ADD_GAIN = 0.3  # share of the current set's excess chi-square an added effect must remove
NO_WORSE = 1.25  # no signal's chi-square may rise by more than this factor when an effect is added
CANDIDATES_PER_ROUND = 4  # best-screened effects refitted in each round
MAX_EFFECTS = 3  # at most this many effects in one explanation
# s: a replay's misfit comes in bursts (one stick-slip event the replay makes and the bench did not, or the
# reverse: 1-2 s, fit.HAC_SECONDS); one such burst, which no effect removes, can hold most of a set's excess
BURST_WINDOW = 2.0
SET_SIMPLEX_FEV = 8  # simplex evaluations per parameter of a set refit (it starts near the optimum)


def extended_set(current: FitResult, single: FitResult) -> CandidateSet:
    """The set ``extend_fit`` makes: ``current``'s effects, then ``single``'s, then ``base`` when ``current``
    recalibrates the base parameters."""
    recalibrated = [BASE] if any(fp.kind == "base" for fp in current.params) else []
    return CandidateSet.of(CandidateSet.parse(current.name).effects + CandidateSet.parse(single.name).effects + recalibrated)


def full_name(effects, params) -> str:
    """Candidate name of ``effects`` fitted with ``params``: the instrumentation findings and ``base`` among them
    appended (``a+b+instrument:pressure_gain+base``)."""
    instruments = list(dict.fromkeys(fp.key.split(".", 1)[0] for fp in params if fp.kind == INSTRUMENT))
    return CandidateSet.of(list(effects) + instruments + ([BASE] if any(fp.kind == "base" for fp in params) else [])).name


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
    chis = scan_points(ctx, params, starts, keep=1.0)
    i = min(range(len(chis)), key=chis.__getitem__)
    return single.name, chis[i], starts[i], len(starts)


def extend_fit(ctx: FitContext, current: FitResult, single: FitResult, start: list[float] | None = None) -> FitResult:
    """Refit ``current`` (an effect set, possibly with base parameters) with ``single``'s effect added.

    The whole set is refitted (the first effects move with the added one), starting at ``start``
    (the screen's best point) or, without it, at the best of ``_start_points``.
    """
    params, starts = _start_points(current, single)
    if start is None:
        chis = scan_points(ctx, params, starts, keep=1.0)
        start = starts[min(range(len(chis)), key=chis.__getitem__)]
    name = full_name(CandidateSet.parse(current.name).effects + CandidateSet.parse(single.name).effects, params)
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
    names = CandidateSet.parse(fit.name).effects
    if len(names) < 1:
        return out
    for e in names:
        keep = [(fp, v) for fp, v in zip(fit.params, fit.values) if fp.effect != e]
        vec, _ = ctx.residual(tuple(fp for fp, _ in keep), [v for _, v in keep])
        out[e] = float(vec @ vec) - fit.chi2
    return out


def reduced_sets(current: FitResult, instrument: FitResult | None) -> list[tuple[str, tuple, list[float]]]:
    """(name, parameters, start) of ``current`` without each of its effects in turn, ``instrument``'s finding on top.

    The start is the set's own optimum for the parameters kept and the finding's single fit (its values
    where the plant is nominal); a finding already in the set keeps the set's value.
    """
    extra = [(fp, v) for fp, v in zip(instrument.params, instrument.values)] if instrument is not None else []
    out = []
    for e in CandidateSet.parse(current.name).effects:
        kept = [(fp, v) for fp, v in zip(current.params, current.values) if fp.effect != e]
        have = {fp.key for fp, _ in kept}
        kept += [(fp, v) for fp, v in extra if fp.key not in have]
        params = tuple(fp for fp, _ in kept)
        out.append((full_name([x for x in CandidateSet.parse(current.name).effects if x != e], params), params, [v for _, v in kept]))
    return out


def prune(fits: dict, winner: str, n: int, run) -> tuple[str, list[dict]]:
    """Backward elimination of the winning set's effects against the instrumentation (module doc).

    ``fits``: every fitted candidate (name -> FitResult; the instrumentation singles among them);
    ``run(sets)`` fits ``(name, params, start)`` triples into ``fits``. Returns the winner
    (the set, or the best reduced set it does not beat) and the rounds in the search log's form.
    """
    scores = score_all(fits, n)
    found = [k for k in fits if is_instrument(k) and beats(scores, k, "nominal", n)]
    instrument = fits[min(found, key=lambda k: scores[k].bic)] if found else None
    log = []
    while len(CandidateSet.parse(winner).effects) > 1:
        sets = reduced_sets(fits[winner], instrument)
        if any(name not in fits for name, _, _ in sets):
            run([s for s in sets if s[0] not in fits])
        scores = score_all(fits, n)
        tried = [name for name, _, _ in sets]
        level = [k for k in tried if not beats(scores, winner, k, n)]  # the set does not beat it
        best = min(level, key=lambda k: scores[k].bic, default=None)
        words = (f"{' and '.join(e for e in CandidateSet.parse(winner).effects if e not in CandidateSet.parse(best).effects)} does not beat "
                 f"{best} (BIC {scores[best].bic - scores[winner].bic:+.0f})" if best else
                 "every effect of the set beats the set without it" + (f" and {instrument.name}" if instrument else ""))
        log.append({"round": "prune", "tried": tried, "best": best or winner, "kept": best is not None, "why": words})
        if best is None:
            break
        winner = best
    return winner, log


__all__ = ["extend_fit", "prune", "reduced_sets", "full_name", "adds_enough", "contributions", "extended_set", "ADD_GAIN", "NO_WORSE",
           "CANDIDATES_PER_ROUND", "MAX_EFFECTS", "screen_addition", "burst_trimmed", "BURST_WINDOW"]

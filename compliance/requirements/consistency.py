"""Limits of one requirement set that cannot hold together, found before any simulation.

Two pairs are checked, with the arithmetic in the finding:

- a time-constant window and a speed limit on the same step procedure: reaching 63.2 % of a step
  h within tau_max needs a mean speed of at least 0.632 h / tau_max, and a peak speed over any
  window shorter than that time is at least that mean, so when 0.632 h / tau_max exceeds the
  speed limit no servo can pass both (``conflict``). A first-order answer starts at h / tau, so when
  h / tau_max reaches the limit only a servo that is rate limited on that step can pass both, and its
  time constant is then a rate-limit figure (``tension``);
- a full-stroke time window and a speed limit on the same full-stroke procedure: the straight part
  of a stroke of time T moves at L / T (25-75 % rule), and the peak speed is at least that, so a
  stroke time below L / v fails the speed limit. A window wholly below L / v is a ``conflict``; a
  window whose lower edge is below it is narrowed to [L / v, high] (``narrowing``);
- a time-constant window on steps and a rate limit judged on full strokes only (a different
  procedure): when 0.632 h / tau_max exceeds the rate limit, the servo must move faster on those
  steps than the strokes may, so both pass only when the device that limits the stroke rate does
  not act on the steps (flow-control valves out where tau is measured, as a hydraulic servomotor's
  rate limits are kept apart from its time constant in IEEE Std 1207-2011); a set-point rate
  limiter at or below the stroke limit acts on every step and fails the window (``rate_split``).

A conflict between two mandatory requirements stops ``govcheck check`` with exit code 2 (the
requirement set is invalid input) unless ``--allow-conflicts`` is given; every finding is reported in
the results (``findings``). docs/requirements.md, "Consistency of a requirement set".
"""

from __future__ import annotations

import math

from compliance.errors import InputError
from compliance.requirements.verdict import Severity

__all__ = ["CONFLICT", "NARROWING", "RATE_SPLIT", "TENSION", "check_consistency", "consistency_findings"]

CONFLICT, TENSION, NARROWING, RATE_SPLIT = "conflict", "tension", "narrowing", "rate_split"
_TAU_FRACTION = 1.0 - math.exp(-1.0)  # 63.2 %, as metrics.step.TAU_FRACTION
_SPEEDS = {"max_speed": None, "max_opening_speed": "opening", "max_closing_speed": "closing", "stroke_speed": None}
_STROKE_TIMES = {"opening_time": "opening", "closing_time": "closing"}


def _upper(req, stroke):
    """The upper limit of a requirement with <=, < or within (SI), else None."""
    if req.limit is None or not req.enabled:
        return None
    lim = req.resolved_limit(stroke)
    return lim[-1] if req.comparator in ("<=", "<", "within") else None


def _lower(req, stroke):
    """The lower limit of a requirement with >=, > or within (SI), else None."""
    if req.limit is None or not req.enabled:
        return None
    lim = req.resolved_limit(stroke)
    return lim[0] if req.comparator in (">=", ">", "within") else None


def _finding(kind, a, b, procedure, text, **figures) -> dict:
    return {"kind": kind, "requirements": [a.id, b.id], "procedure": procedure, "text": text,
            "mandatory": a.severity == Severity.MANDATORY and b.severity == Severity.MANDATORY, **figures}


def _tau_vs_speed(reqset, stroke, tau_req, v_req) -> list[dict]:
    out = []
    tau_max, v = _upper(tau_req, stroke), _upper(v_req, stroke)
    if tau_max is None or v is None or v_req.metric == "stroke_speed" or tau_req.source != "simulation":
        return out
    for p in sorted(set(tau_req.procedures) & set(v_req.procedures)):
        proc = reqset.procedures[p]
        if proc.kind != "steps":
            continue
        h = proc.settings["size"].resolve(stroke)
        mean, first = _TAU_FRACTION * h / tau_max, h / tau_max
        head = (f"{tau_req.id} (time constant <= {tau_max:.3g} s) and {v_req.id} ({v_req.metric} <= {v * 1e3:.1f} mm/s) "
                f"on {p} (steps of {h * 1e3:.2f} mm): ")
        fig = {"step": h, "tau_max": tau_max, "v_max": v, "mean_speed": mean, "first_order_peak": first}
        if mean > v:
            out.append(_finding(CONFLICT, tau_req, v_req, p, **fig, text=head + (
                f"reaching 63.2 % of {h * 1e3:.2f} mm within {tau_max:.3g} s needs a mean speed of 0.632 x {h * 1e3:.2f} mm / "
                f"{tau_max:.3g} s = {mean * 1e3:.1f} mm/s > {v * 1e3:.1f} mm/s, and the peak speed is at least the mean: "
                "no servo can pass both")))
        elif first >= v:
            out.append(_finding(TENSION, tau_req, v_req, p, **fig, text=head + (
                f"a first-order answer meeting the window starts at h / tau >= {h * 1e3:.2f} mm / {tau_max:.3g} s = "
                f"{first * 1e3:.1f} mm/s >= {v * 1e3:.1f} mm/s: only a servo rate limited on this step can pass both, "
                "and its time constant is then a rate-limit figure")))
    return out


def _time_vs_speed(reqset, stroke, t_req, v_req) -> list[dict]:
    out = []
    v = _upper(v_req, stroke)
    direction = _SPEEDS[v_req.metric]
    if v is None or v <= 0 or (direction and direction != _STROKE_TIMES[t_req.metric]) or t_req.limit is None or not t_req.enabled:
        return out
    t_min = stroke / v  # the fastest stroke time the speed limit allows
    lo, hi = _lower(t_req, stroke), _upper(t_req, stroke)
    for p in sorted(set(t_req.procedures) & set(v_req.procedures)):
        if reqset.procedures[p].kind != "full_stroke":
            continue
        who = f"{t_req.id} ({t_req.metric} {t_req.limit_text}) and {v_req.id} ({v_req.metric} <= {v * 1e3:.1f} mm/s) on {p}"
        why = (f": a stroke of time T moves at L / T on its straight part, so T < {stroke * 1e3:.0f} mm / {v * 1e3:.1f} mm/s = "
               f"{t_min:.3g} s fails the speed limit")
        if hi is not None and hi < t_min:
            out.append(_finding(CONFLICT, t_req, v_req, p, who + f" cannot both pass: the window ends at {hi:.3g} s" + why))
        elif lo is not None and lo < t_min:
            admit = f"{t_min:.3g} s .. {hi:.3g} s" if hi is not None else f">= {t_min:.3g} s"
            out.append(_finding(NARROWING, t_req, v_req, p, who + f" together admit only {admit}" + why,
                                t_min=t_min, t_max=hi, v_max=v))
    return out


def _circuit(reqset, points) -> set:
    """The flow-control settings (True installed, False out, None as configured) of the named operating points."""
    return {reqset.operating_points[o].flow_control for o in points}


def _tau_vs_rate_limit(reqset, stroke, tau_req, v_req) -> list[dict]:
    """A time-constant window on steps against a rate limit judged on full strokes only (``rate_split``)."""
    tau_max, v = _upper(tau_req, stroke), _upper(v_req, stroke)
    if tau_max is None or v is None or v <= 0 or tau_req.source != "simulation":
        return []
    if not any(reqset.procedures[p].kind == "full_stroke" for p in v_req.procedures):
        return []
    valves_out = _circuit(reqset, tau_req.operating_points) == {False} and False not in _circuit(reqset, v_req.operating_points)
    limiter_out = {reqset.operating_points[o].setpoint_limiter for o in tau_req.operating_points} == {False}
    out = []
    for p in sorted(set(tau_req.procedures) - set(v_req.procedures)):
        proc = reqset.procedures[p]
        if proc.kind != "steps":
            continue
        h = proc.settings["size"].resolve(stroke)
        mean = _TAU_FRACTION * h / tau_max
        if mean <= v:
            continue
        circuit = ("the file measures tau with the flow-control valves out and the strokes with them in, so the valves "
                   "may set the stroke rate" if valves_out else
                   "tau and the strokes are judged on the same circuit, so the device that limits the stroke rate must not act on these steps")
        limiter = (f"The file injects these steps downstream of the set-point rate limiter, so a limiter at or below "
                   f"{v * 1e3:.1f} mm/s may set the stroke rate too (as commissioned it would ramp them: tau >= 0.632 x "
                   f"{h * 1e3:.2f} mm / {v * 1e3:.1f} mm/s = {_TAU_FRACTION * h / v:.3f} s > {tau_max:.3g} s)" if limiter_out else
                   f"A set-point rate limiter at or below {v * 1e3:.1f} mm/s acts on every step and gives tau >= 0.632 x "
                   f"{h * 1e3:.2f} mm / {v * 1e3:.1f} mm/s = {_TAU_FRACTION * h / v:.3f} s > {tau_max:.3g} s")
        out.append(_finding(RATE_SPLIT, tau_req, v_req, p, step=h, tau_max=tau_max, v_max=v, mean_speed=mean,
                            ramp_tau_min=_TAU_FRACTION * h / v, text=(
            f"{tau_req.id} (time constant <= {tau_max:.3g} s on {p}, steps of {h * 1e3:.2f} mm) and {v_req.id} "
            f"({v_req.metric} <= {v * 1e3:.1f} mm/s on full strokes): reaching 63.2 % of the step within {tau_max:.3g} s needs "
            f"a mean speed of 0.632 x {h * 1e3:.2f} mm / {tau_max:.3g} s = {mean * 1e3:.1f} mm/s > {v * 1e3:.1f} mm/s, so the "
            f"servo must move faster on these steps than the strokes may: {circuit}. {limiter}")))
    return out


def _interval(req, stroke):
    """(low, high, low strict, high strict) of the values ``req`` admits (SI); None for an open side."""
    lim = req.resolved_limit(stroke)
    c = req.comparator
    if c == "within":
        return lim[0], lim[-1], False, False
    if c in ("<=", "<"):
        return None, lim[0], False, c == "<"
    if c in (">=", ">"):
        return lim[0], None, c == ">", False
    return None, None, False, False


def _shared_cases(a, b) -> list[tuple[str, str]]:
    """(procedure, operating point) pairs both requirements judge (a point a requirement declares not applicable is left out)."""
    return [(p, o) for p in a.procedures if p in b.procedures for o in a.operating_points
            if o in b.operating_points and o not in a.not_applicable and o not in b.not_applicable]


def _disjoint_windows(stroke, a, b) -> list[dict]:
    """Two limits on the same metric and reading whose admissible intervals do not overlap (``conflict``)."""
    if a.metric != b.metric or a.source != b.source or a.options != b.options:
        return []
    cases = _shared_cases(a, b)
    if not cases:
        return []
    lo_a, hi_a, slo_a, shi_a = _interval(a, stroke)
    lo_b, hi_b, slo_b, shi_b = _interval(b, stroke)
    los = [(v, s) for v, s in ((lo_a, slo_a), (lo_b, slo_b)) if v is not None]
    his = [(v, s) for v, s in ((hi_a, shi_a), (hi_b, shi_b)) if v is not None]
    if not los or not his:
        return []
    lo, lo_strict = max(los, key=lambda x: (x[0], x[1]))
    hi, hi_strict = min(his, key=lambda x: (x[0], not x[1]))
    if lo < hi or (lo == hi and not (lo_strict or hi_strict)):
        return []
    p, o = cases[0]
    more = f" (and {len(cases) - 1} more)" if len(cases) > 1 else ""
    return [_finding(CONFLICT, a, b, p, low=lo, high=hi, text=(
        f"{a.id} ({a.metric} {a.limit_text}) and {b.id} ({b.metric} {b.limit_text}) judge the same {a.metric} on {p} at "
        f"{o}{more}, and no value lies in both: together they admit only values >= {lo:.6g} and <= {hi:.6g} (SI), "
        "an empty window"))]


def consistency_findings(reqset, stroke: float) -> list[dict]:
    """Every pair of limits in ``reqset`` that cannot hold together or narrow each other.

    Parameters
    ----------
    reqset : RequirementSet
    stroke : float
        The servomotor stroke [m] (resolves per-cent-of-stroke limits and step sizes).

    Returns
    -------
    list of dict
        ``{"kind": conflict|tension|narrowing|rate_split, "requirements": [id, id], "procedure", "text", "mandatory"}``,
        with the figures of the arithmetic [SI] on the step findings (``step``, ``tau_max``, ``v_max``, ``mean_speed``).
    """
    reqs = [r for r in reqset.requirements if r.enabled and r.limit is not None]
    out = []
    for i, a in enumerate(reqs):
        for b in reqs[i + 1:]:
            out += _disjoint_windows(stroke, a, b)
    for a in reqs:
        for b in reqs:
            if b.metric not in _SPEEDS:
                continue
            if a.metric == "time_constant":
                out += _tau_vs_speed(reqset, stroke, a, b) + _tau_vs_rate_limit(reqset, stroke, a, b)
            elif a.metric in _STROKE_TIMES:
                out += _time_vs_speed(reqset, stroke, a, b)
    return out


def check_consistency(reqset, stroke: float, allow_conflicts: bool = False) -> list[dict]:
    """The findings of :func:`consistency_findings`; a conflict between mandatory requirements is invalid input.

    Raises
    ------
    InputError
        Two mandatory requirements no servo can pass together (exit code 2), unless ``allow_conflicts``.
    """
    found = consistency_findings(reqset, stroke)
    bad = [f for f in found if f["kind"] == CONFLICT and f["mandatory"]]
    if bad and not allow_conflicts:
        raise InputError(f"{reqset.path}: the requirement set contradicts itself: " + "; ".join(f["text"] for f in bad)
                         + ". Change one of the readings (docs/requirements.md, 'Readings') or give --allow-conflicts "
                         "to judge it anyway")
    return found

"""The governor settings a commissioning engineer derives from a requirement file, checked the way ``check`` reads it.

Shared by ``govcheck size`` and the remedies search (``check --remedies``); every step measures with
the requirement file's own readings (its time-constant points, steps and ``travel``, its stroke-time
windows), so what the design aims at is what the check judges:

1. **Set-point rate limiter** (the device that sets the stroke times in service; IEEE PES TR 2013
   gate-rate limits, one rate per direction, so opening and closing are adjusted independently):
   each direction's rate gives a full-rate stroke in the file's window without exceeding its stroke-
   rate limit: R = min(L / T_low, v_limit) x ``RATE_SHARE`` (our choice: just under the faster edge, since
   a loaded gate follows the ramp a little slower). A ramp hold of ``LEAD_FRACTION`` of the stroke
   keeps the set-point from running away from a gate held back at breakaway.
2. **Flow-control valves**: opened wide (``THROTTLE_OPEN`` x the valve's own conductance: the series
   exhaust path keeps 1 / sqrt(1 + 1/4) = 89 % of the valve's conductance, ISO 6358 series rule): with
   the limiter setting the rate they are a backstop, not the speed setting.
3. **Time constant**: the file's time-constant requirement is run (its own steps and points, the
   limiter and throttles not acting) and K_P scaled so that the geometric centre of the measured range
   sits at the geometric centre of the window (a type-1 loop: tau ~ 1 / K_P), the closing-side gain
   (``controller.compensation_slope_negative``, the dead-zone inverse's slope) so that the two
   directions' centres agree; repeated up to ``TAU_ITERATIONS`` times.
4. **What cannot be met**: the range of the time constant over the file's points is a property of the
   hardware (the load takes a larger share of the cylinders' force at some points than at others). It
   fits the window with a tolerance margin only when hi / lo <= (tau_max (1 - m)) / (tau_min (1 + m)),
   m = ``TAU_MARGIN``; otherwise the design says so with the arithmetic (``spread``).

The small-signal stability of the result is checked on the linearised loop against the report's
criterion (``STABILITY``: phase margin >= 30 deg, gain margin >= 6 dB at every point the file
linearises); K_D is halved until it holds.
"""

from __future__ import annotations

import dataclasses
import math

from compliance.requirements.verdict import Severity, Status

__all__ = ["LEAD_FRACTION", "RATE_SHARE", "STABILITY", "TAU_MARGIN", "THROTTLE_OPEN", "design_governor", "limiter_settings",
           "stability", "tau_range"]

RATE_SHARE = 0.99
LEAD_FRACTION = 0.08
THROTTLE_OPEN = 2.0
TAU_ITERATIONS = 4
# each end of the window kept 15 % clear: the delivered-unit tolerances the remedies' yield draws move the time
# constant by about the valve conductance's 5 % (one standard deviation) plus the friction's spread; 59 of 59 units
# inside needs about 2.5 standard deviations (our choice)
TAU_MARGIN = 0.15
STABILITY = {"phase_margin_deg": 30.0, "gain_margin_db": 6.0}  # the report's criterion (report.acceptance.MARGIN_CRITERION)
LIMITER_KEYS = ("controller.setpoint_opening_rate", "controller.setpoint_closing_rate", "controller.setpoint_lead_limit")
THROTTLE_KEYS = ("flow_control.opening_conductance", "flow_control.closing_conductance")


def _window(reqset, metric: str, stroke: float):
    for r in reqset.requirements:
        if r.metric == metric and r.enabled and r.limit is not None and r.severity == Severity.MANDATORY:
            lim = r.resolved_limit(stroke)
            return (lim[0], lim[-1]) if r.comparator == "within" else (None, lim[0])
    return None


def _rate_limit(reqset, stroke: float) -> float | None:
    """The tightest mandatory stroke-rate limit [m/s] (``stroke_speed``), or None."""
    vals = [r.resolved_limit(stroke)[-1] for r in reqset.requirements
            if r.enabled and r.limit is not None and r.metric == "stroke_speed" and r.comparator in ("<=", "<")
            and r.severity == Severity.MANDATORY]
    return min(vals) if vals else None


def limiter_settings(cfg, reqset) -> tuple[dict, dict]:
    """(parameter values, record) of steps 1-2 of the module note: limiter rates, ramp hold, throttles wide open."""
    L = cfg.params["cylinder.stroke"]
    v_lim = _rate_limit(reqset, L)
    values, record = {}, {}
    if v_lim is None and not any(_window(reqset, m, L) for m in ("opening_time", "closing_time")):
        return values, {"limiter": "none: the file sets no stroke time or stroke rate for it to hold"}
    for key, metric in zip(LIMITER_KEYS[:2], ("opening_time", "closing_time")):
        win = _window(reqset, metric, L)
        lo_t = (win[0] if win and win[0] else None) or 5.0
        rate = L / lo_t
        if v_lim:
            rate = min(rate, v_lim)
        values[key] = RATE_SHARE * rate
        record[key] = (f"{values[key] * 1e3:.2f} mm/s = {RATE_SHARE:g} x min(L / T_low = {L * 1e3:.0f} mm / {lo_t:.2f} s"
                       + (f", stroke-rate limit {v_lim * 1e3:.1f} mm/s)" if v_lim else ")"))
    values[LIMITER_KEYS[2]] = LEAD_FRACTION * L
    record[LIMITER_KEYS[2]] = f"{LEAD_FRACTION:.0%} of the stroke"
    c = cfg.params["valve.sonic_conductance"]
    for key in THROTTLE_KEYS:
        values[key] = THROTTLE_OPEN * c
        record[key] = f"wide open: {THROTTLE_OPEN:g} x the valve's conductance (a backstop; the limiter sets the rate)"
    return values, record


def _tau_requirements(reqset):
    return [r for r in reqset.requirements
            if r.metric == "time_constant" and r.enabled and r.source == "simulation" and r.limit is not None
            and r.comparator == "within" and r.severity == Severity.MANDATORY]


def tau_range(cfg, reqset, *, workers=None) -> dict | None:
    """The file's time-constant requirement run on ``cfg``: its window and the evaluated values by direction.

    Returns None when the file has no mandatory time-constant window. Else ``{"window", "up", "down",
    "rows"}``: ``up`` / ``down`` = (lowest, highest) evaluated value [s] of the steps of each direction
    (None when none was eligible), ``rows`` = (run, step, value) of every evaluated row.
    """
    from compliance.campaign.run import run_campaign

    reqs = _tau_requirements(reqset)
    if not reqs:
        return None
    sub = dataclasses.replace(reqset, requirements=tuple(reqs[:1]))
    res = run_campaign(cfg, sub, workers=workers, progress=False)
    e = res["requirements"][0]
    lo, hi = e["limit"]
    by = {"up": [], "down": []}
    rows = []
    for r in e["rows"]:
        if r["status"] in (Status.PASS, Status.FAIL) and r["value"] is not None:
            d = "down" if " down " in (r.get("which") or "") else "up"
            by[d].append(r["value"])
            rows.append((r["run"], r["which"], r["value"]))
    return {"requirement": e["id"], "window": (lo, hi), "rows": rows,
            **{d: ((min(v), max(v)) if v else None) for d, v in by.items()}}


def _geo(a, b):
    return math.sqrt(a * b)


def _spread_text(t: dict) -> str:
    vals = [v for d in ("up", "down") if t[d] for v in t[d]]
    lo, hi = min(vals), max(vals)
    wlo, whi = t["window"]
    fit = (whi * (1 - TAU_MARGIN)) / (wlo * (1 + TAU_MARGIN))
    slow = max(t["rows"], key=lambda r: r[2])
    fast = min(t["rows"], key=lambda r: r[2])
    return (f"the time constant ranges {hi / lo:.2f}:1 over the file's points ({fast[2]:.3f} s at {fast[0]}, "
            f"{slow[2]:.3f} s at {slow[0]}); the window {wlo:.2f}-{whi:.2f} s holds at most {fit:.2f}:1 with "
            f"{TAU_MARGIN:.0%} clear at each end ({whi:.2f} x {1 - TAU_MARGIN:.2f} / ({wlo:.2f} x {1 + TAU_MARGIN:.2f})): no "
            "gain fits it; the spread comes from the load's share of the cylinders' force (a larger bore or a "
            "higher supply lowers it)")


def stability(cfg, reqset) -> list[dict]:
    """Gain and phase margins of the linearised loop at every point of the file that has a position.

    Returns one ``{"operating_point", "phase_margin_deg", "gain_margin_db", "ok"}`` per distinct
    (position, load, circuit); ``ok`` is False when a margin is below :data:`STABILITY` or missing.
    """
    from compliance.errors import GovcheckError
    from compliance.linear.analysis import analyse
    from compliance.simulation.scenario import scenario_load

    out, seen = [], set()
    L = cfg.params["cylinder.stroke"]
    for op in reqset.operating_points.values():
        if op.initial_position is None or op.load == "curve":
            continue
        x0 = op.initial_position.resolve(L)
        key = (round(x0, 6), scenario_load(cfg, op), op.flow_control)
        if key in seen:
            continue
        seen.add(key)
        try:
            a = analyse(cfg, x0, scenario_load(cfg, op), flow_control=op.flow_control, detail=False)
            pm, gm = a.metric("phase_margin_deg"), a.metric("gain_margin_db")
        except GovcheckError:
            pm = gm = None
        ok = pm is not None and gm is not None and pm >= STABILITY["phase_margin_deg"] and gm >= STABILITY["gain_margin_db"]
        out.append({"operating_point": op.name, "phase_margin_deg": pm, "gain_margin_db": gm, "ok": ok})
    return out


def _tune_time_constant(cfg, reqset, record, workers):
    """Step 3 of the module note; appends each measured range to ``record["tau"]``, sets ``record["spread"]``."""
    for _ in range(TAU_ITERATIONS):
        t = tau_range(cfg, reqset, workers=workers)
        if t is None or not (t["up"] or t["down"]):
            return cfg
        p = cfg.params
        record["tau"].append({"kp": p["controller.kp"], "kd": p["controller.kd"],
                              "slope_negative": p["controller.compensation_slope_negative"], "up": t["up"], "down": t["down"]})
        wlo, whi = t["window"]
        g = {d: _geo(*t[d]) for d in ("up", "down") if t[d]}
        vals = [v for d in g for v in t[d]]
        lo, hi = min(vals), max(vals)
        record["spread"] = _spread_text(t) if hi / lo > (whi * (1 - TAU_MARGIN)) / (wlo * (1 + TAU_MARGIN)) else None
        inside = wlo * (1 + TAU_MARGIN) <= lo and hi <= whi * (1 - TAU_MARGIN)
        balanced = len(g) < 2 or abs(math.log(g["up"] / g["down"])) < 0.05
        if inside and balanced:
            return cfg
        new = {"controller.kp": p["controller.kp"] * _geo(lo, hi) / _geo(wlo, whi)}
        if len(g) == 2:  # the closing side's gain ~ 1 / slope: bring its centre onto the opening side's
            new["controller.compensation_slope_negative"] = min(3.0, max(0.5, p["controller.compensation_slope_negative"]
                                                                    * g["up"] / g["down"]))
        # the derivative time K_D / K_P is kept: it sets the phase lead the loop was stable with
        new["controller.kd"] = p["controller.kd"] * new["controller.kp"] / p["controller.kp"]
        cfg = cfg.replace(params=new)
    return cfg


def design_governor(cfg, reqset, *, workers=None, tune=True) -> tuple:
    """``cfg`` with the governor settings of the module note, and the design record.

    Returns
    -------
    tuple
        (configuration, record): ``record`` has ``limiter`` (value -> why), ``tau`` (each iteration's
        range), ``stability`` (margins per point), ``spread`` (the arithmetic when the time-constant
        range cannot fit the window with its margin, else None).
    """
    values, why = limiter_settings(cfg, reqset)
    if values:
        cfg = cfg.replace(params=values)
    record = {"limiter": why, "tau": [], "stability": [], "spread": None}
    if not tune:
        return cfg, record
    for _ in range(3):
        cfg = _tune_time_constant(cfg, reqset, record, workers)
        record["stability"] = stability(cfg, reqset)
        if all(s["ok"] for s in record["stability"]) or cfg.params["controller.kd"] <= 0.0:
            break
        # the derivative gain rings the pneumatic resonance first: halve it and tune the time constant again
        cfg = cfg.replace(params={"controller.kd": 0.5 * cfg.params["controller.kd"]})
    return cfg, record


# stall band of the dead-zone inverse ~ its smoothing width lc (model.pid_controller.stall_error): a positioning
# or tracking error beyond the accuracy is narrowed by this factor on lc per round (our choice)
LC_FACTOR = 0.6
_POSITIONING = ("tracking_max_error", "max_positioning_error")


def _mandatory_failures(results) -> list[dict]:
    return [e for e in results["requirements"]
            if e["severity"] == Severity.MANDATORY and e["status"] in (Status.FAIL, Status.UNCERTAIN)]


def _worst(e) -> dict:
    return e.get("worst") or {}


def corrections(cfg, reqset, results) -> tuple[dict, list[str]]:
    """Parameter changes that answer the failing mandatory requirements of ``results``, with the reason of each.

    Stroke time or stroke rate: the failing direction's limiter rate, scaled by the measured time over the
    middle of the window and never above the stroke-rate limit; positioning or tracking error: the dead-zone
    inverse's smoothing width (its stall band) narrowed by :data:`LC_FACTOR`. Empty when no rule applies.
    """
    L = cfg.params["cylinder.stroke"]
    v_lim = _rate_limit(reqset, L)
    new, why = {}, []
    for e in _mandatory_failures(results):
        w = _worst(e)
        label = (w.get("which") or "")
        d = "opening" if label.startswith("opening") else "closing" if label.startswith("closing") else None
        if e["metric"] in ("opening_time", "closing_time") and w.get("value"):
            d = e["metric"].split("_")[0]
            lo, hi = e["limit"]
            lo = max(lo, L / v_lim) if v_lim else lo
            key = LIMITER_KEYS[0 if d == "opening" else 1]
            rate = new.get(key, cfg.params[key]) * w["value"] / (0.5 * (lo + hi))
            if v_lim:
                rate = min(rate, RATE_SHARE * v_lim)
            if abs(rate / cfg.params[key] - 1.0) > 1e-3:
                new[key] = rate
                why.append(f"{e['id']} {w['value']:.2f} s at {w.get('operating_point')}: {d} rate "
                           f"{cfg.params[key] * 1e3:.2f} -> {rate * 1e3:.2f} mm/s")
            elif cfg.params[key] > 0.0:  # the rate is at its cap: the gate lags the limited set-point under this load
                lag = w["value"] * cfg.params[key] / L - 1.0
                why.append(f"{e['id']} {w['value']:.2f} s at {w.get('operating_point')}: the {d} rate is at its cap "
                           f"{cfg.params[key] * 1e3:.2f} mm/s ({RATE_SHARE:g} x the {v_lim * 1e3:.1f} mm/s stroke-rate limit) "
                           f"and the gate lags the limited set-point by {100 * lag:.1f} % under this load "
                           f"({L * 1e3:.0f} mm / {cfg.params[key] * 1e3:.2f} mm/s = {L / cfg.params[key]:.2f} s): no rate "
                           "fixes it; a lower load share (larger bore, higher supply) or a stiffer loop does")
        elif e["metric"] == "stroke_speed" and w.get("value") and d:
            key = LIMITER_KEYS[0 if d == "opening" else 1]
            rate = new.get(key, cfg.params[key]) * e["limit"][0] / w["value"] * RATE_SHARE
            new[key] = rate
            why.append(f"{e['id']} {w['value'] * 1e3:.1f} mm/s: {d} rate -> {rate * 1e3:.2f} mm/s")
        elif e["metric"] in _POSITIONING and "controller.compensation_width" not in new:
            lc = cfg.params["controller.compensation_width"]
            new["controller.compensation_width"] = LC_FACTOR * lc
            why.append(f"{e['id']} {w.get('value', 0) * 1e3:.2f} mm at {w.get('operating_point')}: the dead-zone inverse's "
                       f"smoothing width {lc:.2f} -> {LC_FACTOR * lc:.2f} V (its stall band shrinks in proportion)")
    return new, why


def design_and_check(cfg, reqset, *, workers=None, rounds: int = 3, progress=False) -> tuple:
    """:func:`design_governor`, then check the full campaign and correct (:func:`corrections`) until it passes.

    Returns
    -------
    tuple
        (configuration, record, results of its last check). ``record["rounds"]`` lists each round's
        failing requirements and the corrections made; ``record["cannot"]`` names what could not be met
        and why (the time-constant spread arithmetic, or the last failures with no rule left), else None.
    """
    from compliance.campaign.run import run_campaign

    cfg, record = design_governor(cfg, reqset, workers=workers)
    record["rounds"], record["cannot"] = [], None
    results = None
    for _ in range(rounds + 1):
        results = run_campaign(cfg, reqset, workers=workers, progress=progress)
        failing = [e["id"] for e in _mandatory_failures(results)]
        if not failing:
            break
        new, why = corrections(cfg, reqset, results)
        record["rounds"].append({"failing": failing, "corrections": why})
        record["why_not"] = [w for w in why if "no rate fixes it" in w]
        if not new or len(record["rounds"]) > rounds:
            break
        cfg = cfg.replace(params=new)
        if "controller.compensation_width" in new:
            cfg = _tune_time_constant(cfg, reqset, record, workers)
    failing = [e for e in _mandatory_failures(results)]
    if failing:
        parts = ([record["spread"]] if record.get("spread") else []) + list(record.get("why_not") or [])
        for e in failing:
            w = _worst(e)
            parts.append(f"{e['id']} {e['status']} ({w.get('display', {}).get('value') if isinstance(w.get('display'), dict) else w.get('value')} "
                         f"at {w.get('run')})")
        record["cannot"] = "; ".join(p for p in parts if p)
    return cfg, record, results

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
3. **Integral action**: K_I = K_P / T_I with T_I = ``INTEGRAL_TIME_FACTOR`` x the window's centre time
   constant (our choice): the integral removes the stall band a mismatch between the valve's dead zone
   and its compensation leaves, which a proportional gain the time-constant window allows cannot.
4. **Time constant** (``campaign.commissioning.tune_loop_gain``): the file's time-constant requirement is
   run (its own steps and points, the limiter and throttles not acting) and K_P (K_I, K_D in proportion)
   scaled so that the geometric centre of the measured range sits at the geometric centre of the window,
   the closing side's slope so that the two directions' centres agree.
5. **Stroke times** (``campaign.commissioning.tune_limiter_rates``): each direction's rate is then set on
   the file's own full strokes, timed the way the check times them.
6. **What cannot be met**: the range of the time constant over the file's points is a property of the
   hardware (the load takes a larger share of the cylinders' force at some points than at others). It
   fits the window with a tolerance margin only when hi / lo <= (tau_max (1 - m)) / (tau_min (1 + m)),
   m = ``TAU_MARGIN``; otherwise the design says so with the arithmetic (``spread``).

Steps 4 and 5 are what a commissioning engineer does on site: the designed file declares them
(``[commissioning] settings = ["loop_gain", "limiter_rates"]``, ``model.assumptions``), so its check
makes them again at each end of each declared range before judging (``campaign.uncertainty``).

The small-signal stability of the result is checked on the linearised loop against the report's
criterion (``STABILITY``: phase margin >= 30 deg, gain margin >= 6 dB at every point the file
linearises); K_D is halved until it holds.
"""

from __future__ import annotations

import math

from compliance.campaign.commissioning import (RATE_SHARE, TAU_MARGIN, mandatory_requirements, rate_limit, tau_range,
                                               tune_limiter_rates, tune_loop_gain)
from compliance.model.assumptions import SETTINGS
from compliance.requirements.verdict import Severity, Status

__all__ = ["INTEGRAL_TIME_FACTOR", "LEAD_FRACTION", "RATE_SHARE", "STABILITY", "TAU_MARGIN", "THROTTLE_OPEN",
           "design_governor", "limiter_settings", "mandatory_uncertain", "stability", "tau_range"]

LEAD_FRACTION = 0.04
THROTTLE_OPEN = 2.0
# integral time = this x the window's centre time constant (our choice; the PI rule of thumb keeps the integral
# slower than the loop it sits in): it removes the stall band a dead-zone mismatch leaves, which the proportional
# gain the time-constant window allows cannot (0.14 V of mismatch / 137 V/m = 1 mm of the 1.6 mm accuracy)
INTEGRAL_TIME_FACTOR = 3.0
# the dead-zone inverse's stall band (~ its width / K_P, model.pid_controller.stall_error) = this share of the file's
# positioning accuracy (our choice: half, so a stall band and a tracking lag of the same size still fit)
STALL_SHARE = 0.5
STABILITY = {"phase_margin_deg": 30.0, "gain_margin_db": 6.0}  # the report's criterion (report.acceptance.MARGIN_CRITERION)
LIMITER_KEYS = (*SETTINGS["limiter_rates"].parameters, "controller.setpoint_lead_limit")  # opening, closing, ramp hold
THROTTLE_KEYS = ("flow_control.opening_conductance", "flow_control.closing_conductance")


def _window(reqset, metric: str, stroke: float):
    for r in reqset.requirements:
        if r.metric == metric and r.enabled and r.limit is not None and r.severity == Severity.MANDATORY:
            lim = r.resolved_limit(stroke)
            return (lim[0], lim[-1]) if r.comparator == "within" else (None, lim[0])
    return None


def limiter_settings(cfg, reqset) -> tuple[dict, dict]:
    """(parameter values, record) of steps 1-2 of the module note: limiter rates, ramp hold, throttles wide open."""
    L = cfg.params["cylinder.stroke"]
    v_lim = rate_limit(reqset, L)
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


def _accuracy(reqset, stroke: float) -> float | None:
    """The tightest mandatory positioning or tracking accuracy [m], or None."""
    vals = [r.resolved_limit(stroke)[-1] for r in reqset.requirements
            if r.enabled and r.limit is not None and r.metric in _POSITIONING and r.comparator in ("<=", "<")
            and r.severity == Severity.MANDATORY]
    return min(vals) if vals else None


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
    tau_reqs = mandatory_requirements(reqset, "time_constant", ("within",))
    if tau_reqs:
        lo, hi = tau_reqs[0].resolved_limit(cfg.params["cylinder.stroke"])
        t_i = INTEGRAL_TIME_FACTOR * math.sqrt(lo * hi)
        values["controller.ki"] = cfg.params["controller.kp"] / t_i
        why["controller.ki"] = (f"K_P / T_I, T_I = {INTEGRAL_TIME_FACTOR:g} x the window's centre time constant "
                                f"sqrt({lo:.2f} s x {hi:.2f} s) = {t_i:.3f} s")
    accuracy = _accuracy(reqset, cfg.params["cylinder.stroke"])
    if accuracy:
        values["controller.compensation_width"] = STALL_SHARE * accuracy * cfg.params["controller.kp"]
        why["controller.compensation_width"] = (f"stall band width / K_P = {STALL_SHARE:g} x the {accuracy * 1e3:.2f} mm "
                                                "positioning accuracy (K_P follows the time constant; the width follows K_P)")
    if values:
        cfg = cfg.replace(params=values)
    record = {"limiter": why, "tau": [], "strokes": [], "stability": [], "spread": None}
    if not tune:
        return cfg, record
    for _ in range(3):
        cfg = tune_loop_gain(cfg, reqset, record, workers=workers)
        record["stability"] = stability(cfg, reqset)
        if all(s["ok"] for s in record["stability"]) or cfg.params["controller.kd"] <= 0.0:
            break
        # the derivative gain rings the pneumatic resonance first: halve it and tune the time constant again
        cfg = cfg.replace(params={"controller.kd": 0.5 * cfg.params["controller.kd"]})
    cfg = tune_limiter_rates(cfg, reqset, record, workers=workers)
    return cfg.with_commissioning(("loop_gain", "limiter_rates")), record


# stall band of the dead-zone inverse ~ its smoothing width lc (model.pid_controller.stall_error): a positioning
# or tracking error beyond the accuracy is narrowed by this factor on lc per round (our choice)
LC_FACTOR = 0.6
_POSITIONING = ("tracking_max_error", "max_positioning_error")
_STROKE_METRICS = ("opening_time", "closing_time", "stroke_speed")


def _mandatory_failures(results) -> list[dict]:
    return [e for e in results["requirements"]
            if e["severity"] == Severity.MANDATORY and e["status"] in (Status.FAIL, Status.UNCERTAIN)]


def mandatory_uncertain(results) -> list[str]:
    """Mandatory requirements whose band straddles their limit (an advisory one stops neither a design nor a remedy)."""
    return [e["id"] for e in results["requirements"] if e["severity"] == Severity.MANDATORY and e["status"] == Status.UNCERTAIN]


def _worst(e) -> dict:
    return e.get("worst") or {}


def corrections(cfg, reqset, results) -> tuple[dict, list[str]]:
    """Parameter changes that answer the failing mandatory requirements of ``results``, with the reason of each.

    Stroke time or stroke rate: the failing direction's limiter rate, scaled by the measured time over the
    middle of the window and never above the stroke-rate limit; positioning or tracking error: the dead-zone
    inverse's smoothing width (its stall band) narrowed by :data:`LC_FACTOR`. Empty when no rule applies.
    """
    L = cfg.params["cylinder.stroke"]
    v_lim = rate_limit(reqset, L)
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
    from compliance.campaign.uncertainty import ranged_parameters

    cfg, record = design_governor(cfg, reqset, workers=workers)
    record["rounds"], record["cannot"] = [], None
    results = None
    # checked as the check will judge it: over the declared ranges, re-commissioned at each end of each
    banded = "local" if ranged_parameters(cfg) else None
    for _ in range(rounds + 1):
        # at the file's values first (cheap); over the ranges only once the point values pass
        results = run_campaign(cfg, reqset, workers=workers, progress=progress)
        if banded and not _mandatory_failures(results):
            results = run_campaign(cfg, reqset, workers=workers, progress=progress, uncertainty=banded)
        failing = [e["id"] for e in _mandatory_failures(results)]
        if not failing:
            break
        new, why = corrections(cfg, reqset, results)
        record["rounds"].append({"failing": failing, "corrections": why})
        record["why_not"] = [w for w in why if "no rate fixes it" in w]
        # a stroke time or rate off its limit: the rates are set again on the timed strokes (measured, speed-capped)
        strokes = any(e["metric"] in _STROKE_METRICS for e in _mandatory_failures(results))
        if not (new or strokes) or len(record["rounds"]) > rounds:
            break
        cfg = cfg.replace(params=new) if new else cfg
        if "controller.compensation_width" in new:
            cfg = tune_loop_gain(cfg, reqset, record, workers=workers)
        if strokes:
            cfg = tune_limiter_rates(cfg, reqset, record, workers=workers)
    failing = [e for e in _mandatory_failures(results)]
    if failing:
        parts = [record[k] for k in ("spread", "strokes_why") if record.get(k)] + list(record.get("why_not") or [])
        for e in failing:
            w = _worst(e)
            parts.append(f"{e['id']} {e['status']} ({w.get('display', {}).get('value') if isinstance(w.get('display'), dict) else w.get('value')} "
                         f"at {w.get('run')})")
        record["cannot"] = "; ".join(p for p in parts if p)
    return cfg, record, results

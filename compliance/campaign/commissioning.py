"""Commissioning a design: the settings a plant file declares (``model.assumptions``), made by measurement.

Each setting is made the way a commissioning engineer makes it on site, with the requirement file's
own tests, so what commissioning aims at is what the check judges:

- **loop_gain** (:func:`tune_loop_gain`): the file's time-constant requirement is run (its steps and
  points, the limiting devices not acting) and K_P scaled so that the geometric centre of the measured
  range sits at the geometric centre of the window (a type-1 loop: tau ~ 1 / K_P); K_I, K_D and the
  dead-zone inverse's width follow K_P (the integral and derivative times and the stall band in mm are
  kept, so the loop keeps its shape), and the closing side's
  slope (``controller.compensation_slope_negative``, the dead-zone inverse's gain) brings the two
  directions' centres together; up to ``TAU_ITERATIONS`` rounds.
- **limiter_rates** (:func:`tune_limiter_rates`): the file's mandatory stroke-time and stroke-rate
  requirements are run on their full strokes, and each direction's set-point rate scaled by its measured
  time over the centre of the window the two requirements leave together (a rate-limited stroke: T ~ L /
  rate), never so far that the fastest measured straight-part speed passes ``RATE_SHARE`` of the
  stroke-rate limit (a direction with no stroke time is only slowed below it); up to ``RATE_ITERATIONS``
  rounds.

:func:`commission` makes the declared settings in the order of ``model.assumptions.ORDER``. The
uncertainty bands of a commissioned design use it at each end of each declared range
(``campaign.uncertainty``); ``govcheck size`` and the remedies search use it for their design
(``sweep.sizing.governor_design``).
"""

from __future__ import annotations

import dataclasses
import math

from compliance.campaign.executor import execute
from compliance.campaign.judge import judge
from compliance.campaign.plan import plan
from compliance.model.assumptions import ORDER, SETTINGS
from compliance.requirements.verdict import Severity, Status

__all__ = ["CENTRE_TOLERANCE", "RATE_ITERATIONS", "RATE_SHARE", "TAU_ITERATIONS", "TAU_MARGIN", "commission",
           "mandatory_requirements", "rate_limit", "spread_text", "stroke_window", "tau_range", "tune_limiter_rates",
           "tune_loop_gain"]

TAU_ITERATIONS = 4
# each end of the window kept 15 % clear: the delivered-unit tolerances the remedies' yield draws move the time
# constant by about the valve conductance's 5 % (one standard deviation) plus the friction's spread; 59 of 59 units
# inside needs about 2.5 standard deviations (our choice)
TAU_MARGIN = 0.15
CENTRE_TOLERANCE = 0.03  # the measured range's geometric centre within 3 % of the window's (our choice)
RATE_ITERATIONS = 3
RATE_SHARE = 0.99  # a stroke's speed kept just under the stroke-rate limit (our choice)
LIMITER_KEYS = SETTINGS["limiter_rates"].parameters  # opening, closing
_STROKE_METRICS = ("opening_time", "closing_time")


def mandatory_requirements(reqset, metric: str, comparators: tuple) -> list:
    """The enabled, simulated, mandatory requirements of ``metric`` with a limit and one of ``comparators``."""
    return [r for r in reqset.requirements if r.metric == metric and r.enabled and r.source == "simulation"
            and r.limit is not None and r.comparator in comparators and r.severity == Severity.MANDATORY]


def _judged(cfg, reqset, workers) -> list[dict]:
    """The requirement entries of ``reqset`` run and judged on ``cfg`` (point values: no bands, no vetting)."""
    jobs = plan(reqset)
    outcomes, _ = execute(cfg, reqset, jobs, workers=workers, progress=False)
    return judge(cfg, reqset, list(jobs), list(outcomes))[0]


def tau_range(cfg, reqset, *, workers=None) -> dict | None:
    """The file's time-constant requirement run on ``cfg``: its window and the evaluated values by direction.

    Returns None when the file has no mandatory time-constant window. Else ``{"window", "up", "down",
    "rows"}``: ``up`` / ``down`` = (lowest, highest) evaluated value [s] of the steps of each direction
    (None when none was eligible), ``rows`` = (run, step, value) of every evaluated row.
    """
    reqs = mandatory_requirements(reqset, "time_constant", ("within",))
    if not reqs:
        return None
    sub = dataclasses.replace(reqset, requirements=tuple(reqs[:1]))
    e = _judged(cfg, sub, workers)[0]
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


def spread_text(t: dict) -> str:
    """Why no gain fits the time-constant window: the measured range against what the window holds, with the arithmetic."""
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


def tune_loop_gain(cfg, reqset, record: dict | None = None, *, workers=None):
    """``cfg`` with K_P (K_I, K_D in proportion) and the closing side's slope set on the time-constant steps (module note).

    ``record`` (optional) gets each round's measured range in ``record["tau"]`` and, when the range
    cannot fit the window with its margin, the arithmetic in ``record["spread"]``.
    """
    record = {} if record is None else record
    record.setdefault("tau", [])
    for _ in range(TAU_ITERATIONS):
        t = tau_range(cfg, reqset, workers=workers)
        if t is None or not (t["up"] or t["down"]):
            return cfg
        p = cfg.params
        record["tau"].append({"kp": p["controller.kp"], "kd": p["controller.kd"], "ki": p["controller.ki"],
                              "slope_negative": p["controller.compensation_slope_negative"], "up": t["up"], "down": t["down"]})
        wlo, whi = t["window"]
        g = {d: _geo(*t[d]) for d in ("up", "down") if t[d]}
        vals = [v for d in g for v in t[d]]
        lo, hi = min(vals), max(vals)
        record["spread"] = spread_text(t) if hi / lo > (whi * (1 - TAU_MARGIN)) / (wlo * (1 + TAU_MARGIN)) else None
        # set as a commissioning engineer sets it: the measured range centred on the window's centre, both directions
        # alike (within CENTRE_TOLERANCE), not merely somewhere inside, so every plant ends up equally placed
        centred = abs(math.log(_geo(lo, hi) / _geo(wlo, whi))) < CENTRE_TOLERANCE
        balanced = len(g) < 2 or abs(math.log(g["up"] / g["down"])) < 0.05
        if centred and balanced:
            return cfg
        scale = _geo(lo, hi) / _geo(wlo, whi)
        new = {"controller.kp": p["controller.kp"] * scale}
        if len(g) == 2:  # the closing side's gain ~ 1 / slope: bring its centre onto the opening side's
            new["controller.compensation_slope_negative"] = min(3.0, max(0.5, p["controller.compensation_slope_negative"]
                                                                    * g["up"] / g["down"]))
        # the integral and derivative times K_P / K_I and K_D / K_P are kept: they set the loop's shape; the
        # dead-zone inverse's width follows K_P, so its stall band ~ width / K_P (model.pid_controller) stays in mm
        for k in ("controller.kd", "controller.ki", "controller.compensation_width"):
            new[k] = p[k] * scale
        cfg = cfg.replace(params=new)
    return cfg


def stroke_window(reqset, stroke: float) -> tuple[float, float] | None:
    """The stroke times [s] the mandatory stroke-time windows and the stroke-rate limit admit together, or None.

    A stroke of time T moves at L / T on its straight part, so a stroke-rate limit v raises the window's
    lower edge to L / v (the requirement set's ``narrowing`` finding).
    """
    lows, highs = [], []
    for metric in _STROKE_METRICS:
        for r in mandatory_requirements(reqset, metric, ("within",)):
            lim = r.resolved_limit(stroke)
            lows.append(lim[0])
            highs.append(lim[-1])
    if not lows:
        return None
    lo, hi = max(lows), min(highs)
    v_lim = rate_limit(reqset, stroke)
    if v_lim:
        lo = max(lo, stroke / v_lim)
    return lo, hi


def rate_limit(reqset, stroke: float) -> float | None:
    """The tightest mandatory stroke-rate limit [m/s] (``stroke_speed``), or None."""
    vals = [r.resolved_limit(stroke)[-1] for r in mandatory_requirements(reqset, "stroke_speed", ("<=", "<"))]
    return min(vals) if vals else None


def _direction(metric: str, which: str) -> str | None:
    if metric in _STROKE_METRICS:
        return metric.split("_")[0]
    return "opening" if which.startswith("opening") else "closing" if which.startswith("closing") else None


def tune_limiter_rates(cfg, reqset, record: dict | None = None, *, workers=None):
    """``cfg`` with each direction's set-point rate set on the file's full strokes (module note).

    ``record`` (optional) gets each round's measured times and speeds in ``record["strokes"]``.
    """
    record = {} if record is None else record
    record.setdefault("strokes", [])
    L = cfg.params["cylinder.stroke"]
    window = stroke_window(reqset, L)
    if window is None or not cfg.setpoint_rate_limited:
        return cfg
    v_lim = rate_limit(reqset, L)
    reqs = [r for m in _STROKE_METRICS for r in mandatory_requirements(reqset, m, ("within",))]
    reqs += mandatory_requirements(reqset, "stroke_speed", ("<=", "<"))
    sub = dataclasses.replace(reqset, requirements=tuple(reqs))
    target = 0.5 * (window[0] + window[1])
    for _ in range(RATE_ITERATIONS):
        entries = _judged(cfg, sub, workers)
        times = {"opening": [], "closing": []}
        speeds = {"opening": [], "closing": []}
        for e in entries:
            for r in e["rows"]:
                d = _direction(e["metric"], r.get("which") or "")
                if d is None or r.get("value") is None or r["status"] not in (Status.PASS, Status.FAIL):
                    continue
                (times if e["metric"] in _STROKE_METRICS else speeds)[d].append(r["value"])
        record["strokes"].append({"rates": {k: cfg.params[k] for k in LIMITER_KEYS},
                                  "times": {d: (min(v), max(v)) for d, v in times.items() if v}})
        record["strokes_why"] = _spread_why(times, speeds, window, v_lim)
        new = {}
        for key, d in zip(LIMITER_KEYS, ("opening", "closing")):
            rate = cfg.params[key]
            if rate <= 0.0:
                continue
            # a timed direction is set to the window's centre; one only the stroke-rate limit judges is slowed below it
            scale = 0.5 * (min(times[d]) + max(times[d])) / target if times[d] else 1.0
            if v_lim and speeds[d]:
                scale = min(scale, RATE_SHARE * v_lim / max(speeds[d]))
            if abs(scale - 1.0) > 2e-3:
                new[key] = rate * scale
        if not new:
            return cfg
        cfg = cfg.replace(params=new)
    return cfg


def _spread_why(times: dict, speeds: dict, window: tuple, v_lim: float | None) -> str | None:
    """Why no rate holds a direction's strokes in the window: its times over the file's loads span more than it,
    or the stroke-rate limit holds the rate back while the stroke under another load is still too slow."""
    out = []
    for d, v in times.items():
        if not v:
            continue
        if max(v) - min(v) > window[1] - window[0]:
            out.append(f"the {d} time ranges {min(v):.2f}-{max(v):.2f} s over the file's loads while the window the stroke-time "
                       f"and stroke-rate limits leave is {window[0]:.2f}-{window[1]:.2f} s: one rate cannot hold both (the "
                       "gate lags the set-point more under one load than the other; a lower load share narrows it)")
        elif max(v) > window[1] and v_lim and speeds.get(d) and max(speeds[d]) >= RATE_SHARE * v_lim * (1 - 2e-3):
            out.append(f"the {d} stroke reaches {max(speeds[d]) * 1e3:.1f} mm/s under one of the file's loads (the stroke-rate "
                       f"limit {v_lim * 1e3:.1f} mm/s holds the rate there) and takes {max(v):.2f} s under another, beyond "
                       f"{window[1]:.2f} s: one rate cannot hold both (a lower load share narrows the difference)")
    return "; ".join(out) or None


_TUNERS = {"loop_gain": tune_loop_gain, "limiter_rates": tune_limiter_rates}


def commission(cfg, reqset, settings=None, *, workers=None, record: dict | None = None):
    """``cfg`` with its declared commissioning settings made by measurement (``model.assumptions``).

    Parameters
    ----------
    cfg : PlantConfig
    reqset : RequirementSet
        The requirement file whose tests set them.
    settings : sequence of str, optional
        Setting names (default: ``cfg.commissioning``), made in ``model.assumptions.ORDER``.
    workers : int, optional
        Pool size for the measuring campaigns (1: in this process).
    record : dict, optional
        Filled with each tuner's rounds.

    Returns
    -------
    PlantConfig
    """
    names = cfg.commissioning if settings is None else tuple(settings)
    for name in ORDER:
        if name in names:
            cfg = _TUNERS[name](cfg, reqset, record, workers=workers)
    return cfg

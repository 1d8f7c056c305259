"""The first stage of ``check --remedies``: the governor design a commissioning engineer would make.

The design of ``sweep.sizing.governor_design`` (set-point rate limiter for the stroke times, flow-control
valves opened wide as a backstop, K_P and the closing-side gain tuned on the file's own time-constant test,
stability against the report's criterion, check-and-correct rounds) is made on the configuration as
given. When it does not pass, the arithmetic says why; a time constant that spreads wider than its
window, a gate that cannot follow the limiter under the load, a tracking error at the rated load all
grow with the share of the cylinders' force the load takes, so the design is repeated with each
catalogue option that lowers that share (a larger bore, a higher supply class), cheapest first. The first
design that passes its full campaign is the remedy (its tolerance yield follows in ``remedies.finish``);
options that cannot lower the share are named with the reason. Nothing passing hands over to the staged
local search (``remedies.staged_search``).
"""

from __future__ import annotations

import math

from compliance.model.parameters import param_handle
from compliance.requirements.verdict import Overall, Severity, Status
from compliance.sweep.remedies.outcome import RemedyStatus

__all__ = ["governor_stage", "load_share"]


def load_share(cfg, reqset) -> float:
    """Largest load of the file's points (the load curve's maximum included) over the cylinders' force at supply [-]."""
    from compliance.simulation.scenario import scenario_load

    forces = [abs(f) for op in reqset.operating_points.values() for f in [scenario_load(cfg, op)] if isinstance(f, float)]
    if cfg.load_curve is not None:
        forces.append(float(max(abs(v) for v in cfg.load_curve[1])))
    p = cfg.params
    area = cfg.piston_area + cfg.rod_side_area if cfg.options.get("cylinder.arrangement") == "tandem" else \
        min(cfg.piston_area, cfg.rod_side_area)
    return max(forces or [0.0]) / (area * (p["air.supply_pressure"] - p["air.atmospheric_pressure"]))


def _changes(given, designed, keys) -> list[dict]:
    out = []
    for k in keys:
        a, b = float(given.params[k]), float(designed.params[k])
        if abs(b - a) > 1e-9 * max(abs(a), abs(b), 1e-30):
            out.append({"path": k, "unit": param_handle(k, "remedy").unit, "from": a, "to": b})
    return out


def _relative_change(changes) -> float:
    """Root-sum-square of the relative changes (a parameter set from zero counts 1)."""
    return math.sqrt(sum(((c["to"] - c["from"]) / abs(c["from"])) ** 2 if c["from"] else 1.0 for c in changes))


def _yield_text(stage) -> str:
    y = stage.get("tolerance_yield")
    if y:
        return f"passes, tolerance yield {y['pass']} of {y['valid']} (lower bound {100 * y['lower_bound']:.1f} %)"
    return str(stage["status"])


def _attempt(cfg, reqset, options, workers):
    from compliance.sweep.sizing.governor_design import design_and_check

    hw = {k: v for o in options for k, v in o.values(cfg).items()}
    base = cfg.replace(params=hw) if hw else cfg
    designed, record, results = design_and_check(base, reqset, workers=workers)
    return hw, designed, record, results


def _valve_for(cfg, option, catalogue, reqset):
    """The cheapest catalogue valve that fills ``option``'s larger cylinders at the stroke rate, or None.

    A larger bore needs proportionally more flow for the same stroke speed (``sizing.size_servo.size_valve``:
    the filling flow at supply density times the valve authority), so a cylinder option is tried with the
    first valve that supplies it when the configuration's own valve does not.
    """
    from compliance.campaign.commissioning import stroke_window
    from compliance.physics.valve_rating import rating_of_conductance
    from compliance.sweep.sizing.size_servo import size_valve

    moved = cfg.replace(params=option.values(cfg))
    p = moved.params
    window = stroke_window(reqset, p["cylinder.stroke"])
    speed = p["cylinder.stroke"] / (window[0] if window else 5.0)
    area = moved.piston_area + moved.rod_side_area if moved.options.get("cylinder.arrangement") == "tandem" else \
        min(moved.piston_area, moved.rod_side_area)
    atm, b = p["air.atmospheric_pressure"], p["valve.critical_pressure_ratio"]
    need = size_valve(area, speed, p["air.supply_pressure"], p["air.supply_temperature"], atm, b)["rating_needed"]
    if rating_of_conductance(p["valve.sonic_conductance"], atm, b) >= need:
        return None
    valves = sorted((o for o in catalogue.options if o.valve_rating is not None and o.valve_rating >= need
                     and o.applies_to(cfg) is None), key=lambda o: o.cost)
    return valves[0] if valves else None


def _binding(results) -> tuple:
    """The mandatory requirement with the smallest margin % in ``results`` and that margin."""
    m = [(e["worst"]["margin_pct"], e["id"]) for e in results["requirements"]
         if e["severity"] == Severity.MANDATORY and e.get("worst") and e["worst"].get("margin_pct") is not None
         and e["status"] in (Status.PASS, Status.FAIL, Status.UNCERTAIN)]
    return (min(m)[1], min(m)[0]) if m else (None, None)


def governor_stage(ctx, cfg, reqset, catalogue, *, workers=None, uncertain=(), run_kw=None, yield_units=0) -> dict:
    """Run the stage (module note); returns a ``remedies`` section (status found or none_found) with ``stages``.

    A design that passes its campaign is yielded (``yield_units`` units drawn with ``uncertain``); one that
    does not show the yield target moves the stage on to the next option, and is the remedy reported (with
    its yield) only when no later one does better.
    """
    from compliance.sweep.remedies.finish import tolerance_yield
    from compliance.sweep.sizing.governor_design import LIMITER_KEYS, THROTTLE_KEYS, mandatory_uncertain

    keys = list(LIMITER_KEYS) + list(THROTTLE_KEYS) + ["controller.kp", "controller.ki", "controller.kd",
                                                       "controller.compensation_width",
                                                       "controller.compensation_slope_negative"]
    share0 = load_share(cfg, reqset)
    tries = [((), "as given")]
    skipped = []
    for o in sorted((o for o in (catalogue.options if catalogue else ()) if o.applies_to(cfg) is None), key=lambda o: o.cost):
        s = load_share(cfg.replace(params=o.values(cfg)), reqset)
        if s < share0 - 1e-9:
            valve = _valve_for(cfg, o, catalogue, reqset) if o.group == "cylinder_bore" else None
            tries.append(((o, valve) if valve else (o,), f"{o.title}: the load's share of the force {share0:.2f} -> {s:.2f}"
                          + (f", with the {valve.title} its filling flow needs" if valve else "")))
        else:
            skipped.append({"option": o.name, "title": o.title,
                            "reason": f"does not lower the load's share of the cylinders' force ({share0:.2f} -> {s:.2f})"})
    stages, closest, best = [], None, None
    for options, why in tries:
        hw, designed, record, results = _attempt(cfg, reqset, options, workers)
        bind, bind_margin = _binding(results)
        failing = results["summary"]["failed_mandatory"] + mandatory_uncertain(results)
        status = results["summary"]["status"]
        named = " + ".join(o.name for o in options)
        stage = {"stage": "governor design" + (f" with {named}" if options else ""), "why": why,
                 "status": status, "failed_mandatory": failing, "design": {k: v for k, v in record.items() if k != "tau"},
                 "tau_iterations": record.get("tau", [])}
        stages.append(stage)
        changes = _changes(cfg, designed, keys)
        pick = {
            "values": {c["path"]: c["to"] for c in changes},
            "changes": changes,
            "change": _relative_change(changes),
            "status": status,
            "binding": failing[0] if failing else bind,
            "binding_margin_pct": None if failing else bind_margin,
            "failed_mandatory": failing,
            "hardware": [{"option": o.name, "group": o.group, "title": o.title, "cost": o.cost} for o in options],
            "hardware_values": hw,
            "cost": sum(o.cost for o in options),
            "design": record,
            "commissioning": list(designed.commissioning),
        }
        for p in list(pick["values"]) + list(hw):
            ctx.paths.setdefault(p, param_handle(p, "remedy"))
        if status == Overall.PASS:
            pick["verified"] = {"status": status, "failed_mandatory": []}
            found = {"status": RemedyStatus.FOUND, "remedy": pick, "closest": None, "stages": stages,
                     "skipped_options": skipped, "evaluated": len(stages) + (yield_units or 0)}
            y = tolerance_yield(found, ctx, cfg, uncertain, run_kw or {}, yield_units) if yield_units else None
            stage["tolerance_yield"] = None if y is None else {k: y[k] for k in (Status.PASS.value, "valid", "lower_bound", "meets")}
            before = "".join(f" {s['stage']}: {s['design'].get('cannot') or _yield_text(s)}." for s in stages[:-1])
            found["note"] = ("the governor design (set-point rate limiter, flow-control valves wide open, time constant "
                             f"tuned on the file's own test) passes a full campaign ({len(results['runs'])} runs) "
                             + (f"with {' + '.join(o.title for o in options)} ({why})." if options else
                                "with the hardware as given.") + before)
            if y is None or y["meets"]:
                return found
            best = found if best is None or y["lower_bound"] > best["tolerance_yield"]["lower_bound"] else best
            continue
        if closest is None or len(failing) < len(closest["failed_mandatory"]):
            closest = pick
    if best is not None:  # passes its campaign everywhere tried, but no design showed the yield target
        best["stages"], best["evaluated"] = stages, len(stages) + yield_units * sum(1 for s in stages if s.get("tolerance_yield"))
        return best
    return {"status": RemedyStatus.NONE_FOUND, "remedy": None, "closest": closest, "stages": stages,
            "skipped_options": skipped, "evaluated": len(stages),
            "note": "; ".join(f"{s['stage']}: {s['design'].get('cannot') or s['status']}" for s in stages)}

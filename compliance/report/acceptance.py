"""The acceptance-test structure of the compliance report: scope, conditions, method, what was not tested, conclusions.

A governor-test engineer reads a test report in the order of a test code (IEC 60308:2024 /
ASME PTC 29-2005 (R2020) test reports): scope and references, the equipment and its identity,
the test conditions, the instrumentation and method, the results against the guarantees, the
departures from the test code, the conditions not tested, the conclusions with a disposition
per failure, the parties, the revision history and the signatures. This module builds each of
those sections from the results dict alone (no simulation here); the template lays them out.
"""

from __future__ import annotations

from compliance.errors import InputError
from compliance.linear.stability import MARGIN_CRITERION as _MARGIN_CRITERION
from compliance.metrics import METRICS
from compliance.metrics.catalogue import STEP_OPTION_DEFAULTS
from compliance.presentation.values import limit_as_written, row_texts
from compliance.requirements.verdict import Status
from compliance.units.amounts import parse_amount
from compliance.units.formatting import fmt_value, unit_text

# The plant paper as its own text gives it (title, laboratory, university); the copy used names no
# authors, venue or year, so the citation says so instead of guessing them.
PLANT_A_PAPER = ("Development of a high power pneumatic servo-positioning system for speed governors of hydraulic "
                 "turbines. Theoretical-experimental study on the test rig of the Laboratory of Hydraulic and Pneumatic "
                 "Systems (LASHIP), Department of Mechanical Engineering, Federal University of Santa Catarina, Brazil "
                 "(400 kW Francis turbine, 50 m head). Authors, venue and year are not printed in the copy used.")
PLANT_B_PAPER = ("Research on the continuous positioning control to servo-pneumatic system (state feedback with "
                 "acceleration and friction observers on a three-axis pneumatic robot). Authors, venue and year are not "
                 "printed in the copy used.")

# Standards by their edition (the developers' guide); which ones a report lists depends on its requirements.
STANDARDS = {
    "IEC 61362": "IEC 61362:2024, Guide to specification of hydraulic turbine governing systems",
    "IEC 60308": "IEC 60308:2024, Hydraulic turbines \u2013 Testing of control systems",
    "IEEE 125": "IEEE 125-2007, Recommended practice for preparation of equipment specifications for speed-governing "
                "of hydraulic turbines intended to drive electric generators",
    "ASME PTC 29": "ASME PTC 29-2005 (R2020), Speed-governing systems for hydraulic turbine-generator units",
    "IEEE 1207": "IEEE 1207-2011, Guide for the application of turbine governing systems for hydroelectric generating units",
}
SMALL_HYDRO = ("IEC 62006:2010, Hydraulic machines \u2013 Acceptance tests of small hydroelectric installations: the "
               "acceptance-test code for units of this size; its governor and load-rejection tests need the installed "
               "unit and are not covered here.")

# Stability criterion of the linear section and page 1: our own choice (compliance.linear.stability)
MARGIN_CRITERION = _MARGIN_CRITERION


def standards_cited(results: dict) -> list[str]:
    """The governor standards the requirement file cites, each by its edition."""
    seen = []
    for e in results["requirement_set"].get("requirements") or []:
        std = str(e.get("standard") or "").replace("ANSI/", "")
        for key, text in STANDARDS.items():
            if key.replace(" ", "") in std.replace(" ", "") and text not in seen:
                seen.append(text)
    return seen


def paper_citation(results: dict) -> str | None:
    """The source paper of a reference plant, fully cited (``None`` for a user's plant)."""
    name = str(results["plant"].get("name") or "")
    if name.startswith("plant-a"):
        return PLANT_A_PAPER
    if name.startswith("plant-b"):
        return PLANT_B_PAPER
    return None


def scope(results: dict) -> dict:
    """What the report covers and what it does not (a servo-positioner test, not a governor test)."""
    kinds = {p.get("kind") for p in (results["requirement_set"].get("procedures") or {}).values()}
    covered = []
    names = {"steps": "small-step response (dead time, time constant, settling, positioning accuracy)",
             "full_stroke": "full-stroke opening and closing times and speeds",
             "independent_adjustment": "independent adjustment of the opening and closing speeds",
             "sine": "tracking of a sinusoidal set-point", "dead_band": "dead band (slow triangular set-point)",
             "hold": "holding a load (drift, limit cycle)"}
    for k in ("steps", "full_stroke", "independent_adjustment", "sine", "dead_band", "hold"):
        if k in kinds:
            covered.append(names[k])
    covered += sorted(str(k).replace("_", " ") for k in kinds if k and k not in names)
    standards = standards_cited(results)
    if not standards:  # not a governor servo (plant B's robot): no gate, no turbine, no small-hydro code
        return {"object": "the servo-pneumatic positioning system as modelled: valves, cylinders and the position "
                          "controller", "covered": covered,
                "excluded": ["tests of the built system", "paths, loads and supply conditions other than the ones of "
                             "section 2.1"], "standards": [], "paper": paper_citation(results)}
    return {
        "object": "the servo-positioner alone: proportional valve, cylinders, meter-out flow-control valves and the "
                  "position controller, driving the wicket-gate ring against the modelled gate load",
        "covered": covered,
        "excluded": ["the speed-governing loop (speed sensing, droop, governor PID) and frequency-response tests",
                     "load rejection and load acceptance of the unit (water hammer, overspeed)",
                     "emergency and quick closure (shut-down devices, closure on loss of air, power or signal)",
                     "the turbine, penstock and generator"],
        "standards": standards + [SMALL_HYDRO],
        "paper": paper_citation(results),
    }


def _position_mm(op: dict, stroke: float | None) -> str:
    x = op.get("initial_position")
    if x is None:
        return "\u2013"
    try:
        si = parse_amount(x, "m", "operating point").resolve(stroke or 0.0)
    except (InputError, TypeError, ValueError):
        return unit_text(str(x))
    return fmt_value(si * 1e3, "mm", 3)


def _load_text(op: dict, params: dict) -> str:
    ld = op.get("load")
    if ld is None:
        return "none"
    if ld == "curve":
        return "gate load curve (assumed)" if params.get("_curve_assumed") else "gate load curve"
    if ld == "nominal":
        f = params.get("load.nominal_force")
        return f"nominal, {fmt_value(f / 1e3, 'kN', 3)}" if isinstance(f, (int, float)) else "nominal"
    if isinstance(ld, (int, float)):
        return fmt_value(ld / 1e3, "kN", 3) + (" closing" if ld > 0 else " opening" if ld < 0 else "")
    return str(op.get("load_text") or ld)


def _throttles(flag, configured: bool) -> str:
    if flag is None:
        return "in" if configured else "out"
    return "in" if flag else "out"


def conditions(results: dict) -> dict:
    """Supply, temperature, the operating points (position, load, throttles in or out) and the procedures' circuits."""
    plant = results["plant"]
    params = {p.get("key"): p.get("value") for p in plant.get("parameters") or [] if isinstance(p, dict)}
    curve = plant.get("load_curve") or {}
    params["_curve_assumed"] = str(curve.get("source") or "assumed") == "assumed" if curve else False
    configured = str((plant.get("options") or {}).get("flow_control.installed", "false")).lower() == "true"
    supply = params.get("air.supply_pressure")
    rows = []
    for name, op in (results["requirement_set"].get("operating_points") or {}).items():
        rows.append({"name": name, "title": op.get("title") or "", "position": _position_mm(op, params.get("cylinder.stroke")),
                     "load": _load_text(op, params), "throttles": _throttles(op.get("flow_control"), configured)})
    procs = []
    for name, p in (results["requirement_set"].get("procedures") or {}).items():
        fc = (p.get("settings") or {}).get("flow_control")
        if fc is not None:
            procs.append(f"{name}: flow-control valves {'in' if fc else 'out'} whatever the operating point says")
    return {
        "supply": fmt_value(supply / 1e5, "bar", 3) + " abs" if isinstance(supply, (int, float)) else "\u2013",
        "temperature": fmt_value(params.get("air.supply_temperature") - 273.15, "\u00b0C", 3)
        if isinstance(params.get("air.supply_temperature"), (int, float)) else "\u2013",
        "atmosphere": fmt_value(params["air.atmospheric_pressure"] / 1e5, "bar", 4) + " abs"
        if isinstance(params.get("air.atmospheric_pressure"), (int, float)) else "\u2013",
        "throttles_configured": "in" if configured else "out",
        "operating_points": rows, "procedure_circuits": procs,
        "curve_assumed": params["_curve_assumed"],
    }


def method_rows(results: dict) -> list[dict]:
    """The instrumentation and method table: how each figure is obtained (solver, sampling, filters, thresholds)."""
    params = {p.get("key"): p.get("value") for p in results["plant"].get("parameters") or [] if isinstance(p, dict)}
    rows = [{"item": "Measurement", "how": "none: every figure is computed by simulating the model (no transducer, "
                                           "no uncertainty of measurement)"}]
    if isinstance(params.get("simulation.step"), (int, float)):
        rows.append({"item": "Solver", "how": f"fixed-step fourth-order Runge\u2013Kutta, step "
                                              f"{fmt_value(params['simulation.step'] * 1e3, 'ms', 3)}"})
    if isinstance(params.get("controller.sample_time"), (int, float)):
        ts = params["controller.sample_time"]
        rows.append({"item": "Controller and recording", "how": f"sampled every {fmt_value(ts * 1e3, 'ms', 3)} "
                                                                 f"({fmt_value(1 / ts, 'Hz', 3)}), zero-order hold on the valve command"})
    if params.get("controller.filter_cutoff"):
        rows.append({"item": "Position filter", "how": f"first order, cut-off {fmt_value(params['controller.filter_cutoff'], 'Hz', 3)}"})
    used = []
    for e in results["requirements"]:
        if e["metric"] not in used:
            used.append(e["metric"])
    for m in used:
        info = METRICS.get(m)
        if info is None:
            continue
        rows.append({"item": m.replace("_", " ").capitalize(), "how": info.meaning})
    if any(m in used for m in ("dead_time", "time_constant", "settling_time")):
        for key in ("detect", "settling_band", "final_window"):
            unit, default, meaning = STEP_OPTION_DEFAULTS[key]
            given = sorted({str(v) for e in results["requirements"] for k, v in (e.get("options") or {}).items() if k == key})
            rows.append({"item": {"detect": "Motion detection", "settling_band": "Settling band",
                                  "final_window": "Settled window"}[key],
                         "how": f"{meaning}: {', '.join(unit_text(g) for g in given) if given else unit_text(default)}"})
    return rows


def not_tested(results: dict) -> list[str]:
    """Conditions a test code would cover that these results do not."""
    cond = conditions(results)
    out = [f"Supply pressure other than {cond['supply']} (in particular the minimum supply pressure at which the "
           "strokes must still be met), and supply droop during a stroke.",
           f"Air temperatures other than {cond['temperature']}; seal friction at low temperature.",
           "Fail-safe behaviour: closure or hold on loss of air supply, electrical power or the position signal.",
           "End-of-stroke cushioning and the gate's closing time in its last per cent (cushion time).",
           "Repeatability over several strokes, wear, and leakage of valves and seals (not modelled unless an effect "
           "adds it).",
           "Operating points other than the ones listed in section 2.1 (other positions, loads, circuits)."]
    return out


def code_deviations(results: dict) -> list[str]:
    """Departures from a test code (IEC 60308 / ASME PTC 29 field tests) that this report makes, stated as such."""
    out = ["The servo-positioner is simulated, not measured: the figures carry the model's assumptions (section 3.2) "
           "instead of a measurement uncertainty."]
    ops = results["requirement_set"].get("operating_points") or {}
    if any(op.get("flow_control") is False for op in ops.values()):
        out.append("Small-step figures (time constant) are taken with the flow-control valves out of the circuit at the "
                   "operating points marked \u2018out\u2019 in section 2.1, as the servo-positioner is specified; the "
                   "installed circuit is used for the strokes.")
    if any(e["metric"] in ("max_speed", "max_opening_speed", "max_closing_speed") for e in results["requirements"]):
        out.append("Speeds are the peak of a centred 20 ms difference of the position, not a chart reading of the "
                   "stroke; start-of-stroke surges therefore count.")
    if any(e["metric"] in ("opening_time", "closing_time") for e in results["requirements"]):
        out.append("Opening and closing times are twice the time between 25 % and 75 % of the stroke (the linear part), "
                   "not end to end; the cushioned end of the stroke is not part of them.")
    for e in results["requirement_set"].get("requirements") or []:
        note = str(e.get("note") or "")
        if "Assumption:" in note:
            out.append(f"{e['id']}: " + note[note.index("Assumption:") + len("Assumption:"):].strip())
    return out


def conclusions(results: dict) -> list[dict]:
    """One row per requirement needing a decision: the finding and an empty disposition (accept / rework / waive)."""
    out = []
    for e in results["requirements"]:
        if e["status"] not in (Status.FAIL, Status.UNCERTAIN, Status.NOT_EVALUATED, Status.OPEN):
            continue
        w = e.get("worst") or {}
        value = row_texts(w, e["metric"])["value"] if w else "\u2013"
        if e["status"] == Status.OPEN:
            finding = f"no limit set; value found {value}"
        elif e["status"] == Status.NOT_EVALUATED:
            finding = "not evaluated (see its page)"
        else:
            finding = f"{value} against {limit_as_written(e)}" + (f" at {w.get('operating_point')}" if w.get("operating_point") else "")
        out.append({"id": e["id"], "status": e["status"], "severity": e["severity"], "finding": finding})
    return out


def parties(identity: dict) -> list[dict]:
    """Who the document involves: purchaser, supplier, test engineer, witness (blanks where not given)."""
    return [{"role": "Purchaser / plant owner", "name": identity.get("owner")},
            {"role": "Supplier of the servo-positioner", "name": identity.get("supplier")},
            {"role": "Prepared by (test engineer)", "name": identity.get("author")},
            {"role": "Witness", "name": identity.get("witness")}]


# --------------------------------------------------------------------------- 6. model validation
def _figure_cells(f: dict) -> dict:
    if f["agreement"] is None:
        word, css = "no measured figure", "neutral"
    elif f["by_construction"]:
        word, css = "by construction", "neutral"
    elif not f["independent"]:
        word, css = f"{f['agreement']} (fitted to it)", "neutral"
    else:
        word, css = f["agreement"], "pass" if f["agreement"] == "agrees" else "fail"
    shown = f.get("display") or {}
    return {"test": f["test"], "metric": f["metric"], "modelled": shown.get("modelled", "\u2013"),
            "measured": shown.get("measured", "\u2013"), "agreement": word, "css": css}


def evidence_sections(results: dict) -> tuple[list[dict], list[dict]]:
    """Section 6's tables: each source of the model evidence with its figures, and the verdicts on contradicted figures."""
    ev = results.get("model_evidence") or {}
    out = []
    for s in ev.get("sources") or []:
        if s["kind"] == "paper":
            out.append({"kind": "paper", "title": "Measured figures of the plant paper", "command": s["command"],
                        "independence": s["independence"].capitalize(), "rows": [_figure_cells(f) for f in s["figures"]]})
        else:
            modes = "; ".join(f"{m.replace('_', ' ')}: {'every window within its limits' if d['pass'] else str(len(d['failed_windows'])) + ' of ' + str(d['windows']) + ' windows outside their limits'}"
                              for m, d in s["modes"].items())
            out.append({"kind": "recording", "title": f"Recording {s['path']}", "command": s["command"],
                        "independence": "A recording of the servo, replayed with the model", "summary": modes})
    judged = {e["id"] for e in results["requirements"] if e["status"] not in (Status.OPEN, Status.DISABLED)}
    return out, [c for c in ev.get("contradicted") or [] if c["requirement"] in judged]

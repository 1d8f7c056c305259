"""The acceptance-test structure of the compliance report: scope, conditions, method, what was not tested, conclusions.

A governor-test engineer reads a test report in the order of a test code (IEC 60308:2024 /
ASME PTC 29-2005 (R2020) test reports): scope and references, the equipment and its identity,
the test conditions, the instrumentation and method, the results against the guarantees, the
departures from the test code, the conditions not tested, the conclusions with a disposition
per failure, the parties, the revision history and the signatures. This module builds each of
those sections from the check's result alone (no simulation here); the template lays them out.
"""

from __future__ import annotations

from compliance.linear.stability import MARGIN_CRITERION as _MARGIN_CRITERION
from compliance.metrics import METRICS
from compliance.metrics.catalogue import STEP_OPTION_DEFAULTS
from compliance.presentation.quantities import fmt_quantity
from compliance.presentation.values import limit_as_written, verdict_texts
from compliance.requirements.verdict import Status
from compliance.results.check_result import CheckResult
from compliance.presentation.numbers import fmt_value, unit_text

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


def standards_cited(result: CheckResult) -> list[str]:
    """The governor standards the requirement file cites, each by its edition."""
    seen = []
    for e in result.requirement_set.requirements:
        std = str(e.standard or "").replace("ANSI/", "")
        for key, text in STANDARDS.items():
            if key.replace(" ", "") in std.replace(" ", "") and text not in seen:
                seen.append(text)
    return seen


def paper_citation(result: CheckResult) -> str | None:
    """The source paper of a reference plant, fully cited (``None`` for a user's plant)."""
    name = str(result.plant.name or "")
    if name.startswith("plant-a"):
        return PLANT_A_PAPER
    if name.startswith("plant-b"):
        return PLANT_B_PAPER
    return None


_PROCEDURE_WORDS = {"steps": "small-step response (dead time, time constant, settling, positioning accuracy)",
                    "full_stroke": "full-stroke opening and closing times and speeds",
                    "independent_adjustment": "independent adjustment of the opening and closing speeds",
                    "sine": "tracking of a sinusoidal set-point", "dead_band": "dead band (slow triangular set-point)",
                    "hold": "holding a load (drift, limit cycle)"}


def scope(result: CheckResult) -> dict:
    """What the report covers and what it does not (a servo-positioner test, not a governor test)."""
    kinds = {p.kind for p in result.requirement_set.procedures.values()}
    covered = [words for k, words in _PROCEDURE_WORDS.items() if k in kinds]
    covered += sorted(str(k).replace("_", " ") for k in kinds if k and k not in _PROCEDURE_WORDS)
    standards = standards_cited(result)
    if not standards:  # not a governor servo (plant B's robot): no gate, no turbine, no small-hydro code
        return {"object": "the servo-pneumatic positioning system as modelled: valves, cylinders and the position "
                          "controller", "covered": covered,
                "excluded": ["tests of the built system", "paths, loads and supply conditions other than the ones of "
                             "section 2.1"], "standards": [], "paper": paper_citation(result)}
    return {
        "object": "the servo-positioner alone: proportional valve, cylinders, meter-out flow-control valves and the "
                  "position controller, driving the wicket-gate ring against the modelled gate load",
        "covered": covered,
        "excluded": ["the speed-governing loop (speed sensing, droop, governor PID) and frequency-response tests",
                     "load rejection and load acceptance of the unit (water hammer, overspeed)",
                     "emergency and quick closure (shut-down devices, closure on loss of air, power or signal)",
                     "the turbine, penstock and generator"],
        "standards": standards + [SMALL_HYDRO],
        "paper": paper_citation(result),
    }


def _position_text(op) -> str:
    """An operating point's SI position (resolved when the result was made) in mm; as written when unresolved."""
    if op.position is not None:
        return fmt_quantity(op.position, "m", "mm")
    return unit_text(op.initial_position) if op.initial_position is not None else "\u2013"


def _load_text(op, curve_assumed: bool) -> str:
    if op.load is None:
        return "none"
    if op.on_curve:
        return "gate load curve (assumed)" if curve_assumed else "gate load curve"
    if op.load == "nominal":
        return f"nominal, {fmt_quantity(op.load_force, 'N', 'kN')}" if op.load_force is not None else "nominal"
    if op.load_force is not None:
        return fmt_quantity(op.load_force, "N", "kN") + (" closing" if op.load_force > 0 else " opening" if op.load_force < 0 else "")
    return str(op.load_text or op.load)


def _throttles(flag, configured: bool) -> str:
    if flag is None:
        return "in" if configured else "out"
    return "in" if flag else "out"


def conditions(result: CheckResult) -> dict:
    """Supply, temperature, the operating points (position, load, throttles in or out) and the procedures' circuits."""
    plant = result.plant
    curve_assumed = plant.load_curve is not None and plant.load_curve.assumed
    configured = str(plant.options.get("flow_control.installed", "false")).lower() == "true"
    rows = [{"name": name, "title": op.title or "", "position": _position_text(op), "load": _load_text(op, curve_assumed),
             "throttles": _throttles(op.flow_control, configured)}
            for name, op in result.requirement_set.operating_points.items()]
    procs = []
    for name, p in result.requirement_set.procedures.items():
        fc = p.settings.get("flow_control")
        if fc is not None:
            procs.append(f"{name}: flow-control valves {'in' if fc else 'out'} whatever the operating point says")
    return {
        "supply": fmt_quantity(plant.value("air.supply_pressure"), "Pa", "bar", suffix=" abs"),
        "temperature": fmt_quantity(plant.value("air.supply_temperature"), "K", "\u00b0C"),
        "atmosphere": fmt_quantity(plant.value("air.atmospheric_pressure"), "Pa", "bar", digits=4, suffix=" abs"),
        "throttles_configured": "in" if configured else "out",
        "operating_points": rows, "procedure_circuits": procs,
        "curve_assumed": curve_assumed,
    }


def method_rows(result: CheckResult) -> list[dict]:
    """The instrumentation and method table: how each figure is obtained (solver, sampling, filters, thresholds)."""
    value = result.plant.value
    rows = [{"item": "Measurement", "how": "none: every figure is computed by simulating the model (no transducer, "
                                           "no uncertainty of measurement)"}]
    if isinstance(value("simulation.step"), (int, float)):
        rows.append({"item": "Solver", "how": f"fixed-step fourth-order Runge\u2013Kutta, step "
                                              f"{fmt_quantity(value('simulation.step'), 's', 'ms')}"})
    ts = value("controller.sample_time")
    if isinstance(ts, (int, float)):
        rows.append({"item": "Controller and recording", "how": f"sampled every {fmt_quantity(ts, 's', 'ms')} "
                                                                 f"({fmt_quantity(1 / ts, 'Hz', 'Hz')}), zero-order hold on the valve command"})
    if value("controller.filter_cutoff"):
        rows.append({"item": "Position filter", "how": f"first order, cut-off {fmt_quantity(value('controller.filter_cutoff'), 'Hz', 'Hz')}"})
    used = list(dict.fromkeys(e.metric for e in result.requirements))
    for m in used:
        info = METRICS.get(m)
        if info is None:
            continue
        rows.append({"item": m.replace("_", " ").capitalize(), "how": info.meaning})
    if any(m in used for m in ("dead_time", "time_constant", "settling_time")):
        for key, item in (("detect", "Motion detection"), ("settling_band", "Settling band"), ("final_window", "Settled window")):
            unit, default, meaning = STEP_OPTION_DEFAULTS[key]
            given = sorted({str(v) for r in result.requirement_set.requirements for k, v in r.options.items() if k == key})
            rows.append({"item": item, "how": f"{meaning}: {', '.join(unit_text(g) for g in given) if given else unit_text(default)}"})
    return rows


def not_tested(result: CheckResult) -> list[str]:
    """Conditions a test code would cover that these results do not."""
    cond = conditions(result)
    return [f"Supply pressure other than {cond['supply']} (in particular the minimum supply pressure at which the "
            "strokes must still be met), and supply droop during a stroke.",
            f"Air temperatures other than {cond['temperature']}; seal friction at low temperature.",
            "Fail-safe behaviour: closure or hold on loss of air supply, electrical power or the position signal.",
            "End-of-stroke cushioning and the gate's closing time in its last per cent (cushion time).",
            "Repeatability over several strokes, wear, and leakage of valves and seals (not modelled unless an effect "
            "adds it).",
            "Operating points other than the ones listed in section 2.1 (other positions, loads, circuits)."]


def code_deviations(result: CheckResult) -> list[str]:
    """Departures from a test code (IEC 60308 / ASME PTC 29 field tests) that this report makes, stated as such."""
    out = ["The servo-positioner is simulated, not measured: the figures carry the model's assumptions (section 3.2) "
           "instead of a measurement uncertainty."]
    metrics = {e.metric for e in result.requirements}
    if any(op.flow_control is False for op in result.requirement_set.operating_points.values()):
        out.append("Small-step figures (time constant) are taken with the flow-control valves out of the circuit at the "
                   "operating points marked \u2018out\u2019 in section 2.1, as the servo-positioner is specified; the "
                   "installed circuit is used for the strokes.")
    if metrics & {"max_speed", "max_opening_speed", "max_closing_speed"}:
        out.append("Speeds are the peak of a centred 20 ms difference of the position, not a chart reading of the "
                   "stroke; start-of-stroke surges therefore count.")
    if metrics & {"opening_time", "closing_time"}:
        out.append("Opening and closing times are twice the time between 25 % and 75 % of the stroke (the linear part), "
                   "not end to end; the cushioned end of the stroke is not part of them.")
    for e in result.requirement_set.requirements:
        note = str(e.note or "")
        if "Assumption:" in note:
            out.append(f"{e.id}: " + note[note.index("Assumption:") + len("Assumption:"):].strip())
    return out


def conclusions(result: CheckResult) -> list[dict]:
    """One row per requirement needing a decision: the finding and an empty disposition (accept / rework / waive)."""
    out = []
    for e in result.requirements:
        if e.status not in (Status.FAIL, Status.UNCERTAIN, Status.NOT_EVALUATED, Status.OPEN):
            continue
        w = e.worst
        value = verdict_texts(e)["value"]
        if e.status == Status.OPEN:
            finding = f"no limit set; value found {value}"
        elif e.status == Status.NOT_EVALUATED:
            finding = "not evaluated (see its page)"
        else:
            finding = f"{value} against {limit_as_written(e)}" + (f" at {w.operating_point}" if w and w.operating_point else "")
        out.append({"id": e.id, "status": e.status, "severity": e.severity, "finding": finding})
    return out


def parties(identity) -> list[dict]:
    """Who the document involves: purchaser, supplier, test engineer, witness (blanks where not given)."""
    return [{"role": "Purchaser / plant owner", "name": identity.get("owner")},
            {"role": "Supplier of the servo-positioner", "name": identity.get("supplier")},
            {"role": "Prepared by (test engineer)", "name": identity.get("author")},
            {"role": "Witness", "name": identity.get("witness")}]


# --------------------------------------------------------------------------- 6. model validation
def _figure_cells(f) -> dict:
    """One measured figure of a paper beside the model's (a ``ComparedFigure``), with its agreement in words."""
    if f.agreement is None:
        word, css = "no measured figure", "neutral"
    elif f.by_construction:
        word, css = "by construction", "neutral"
    elif not f.independent:
        word, css = f"{f.agreement} (fitted to it)", "neutral"
    else:
        word, css = f.agreement, Status.PASS if f.agreement == "agrees" else Status.FAIL  # the row colour of its word
    return {"test": f.test, "metric": f.metric, "modelled": f.display.modelled, "measured": f.display.measured,
            "agreement": word, "css": css}


def _replays(modes) -> str:
    """A recording's replays in words: every window within its limits, or how many are not."""
    return "; ".join(f"{m.replace('_', ' ')}: " + ("every window within its limits" if d["pass"] else
                                                   f"{len(d['failed_windows'])} of {d['windows']} windows outside their limits")
                     for m, d in modes.items())


def evidence_sections(result: CheckResult) -> tuple[list[dict], list]:
    """Section 6's tables: each source of the model evidence with its figures, and the judged verdicts that rest on
    contradicted figures (``ContradictedVerdict`` records)."""
    ev = result.model_evidence
    if ev is None:
        return [], []
    out = []
    for s in ev.sources:
        if s.kind == "paper":
            out.append({"kind": "paper", "title": "Measured figures of the plant paper", "command": s.command,
                        "independence": (s.independence or "").capitalize(), "rows": [_figure_cells(f) for f in s.figures]})
        else:
            out.append({"kind": "recording", "title": f"Recording {s.path}", "command": s.command,
                        "independence": "A recording of the servo, replayed with the model", "summary": _replays(s.modes)})
    judged = {e.id for e in result.requirements if e.status not in (Status.OPEN, Status.DISABLED)}
    return out, [c for c in ev.contradicted if c.requirement in judged]

"""How each verdict is known: modelled, by construction, assumed, or not evaluated.

A figure the model *predicts* is evidence; a figure the configuration was *tuned to give*, or
one that missing physics makes trivially zero, is not. Each verdict row gets

- ``basis``: ``"modelled"`` (the model predicts it from the plant's parameters),
  ``"by_construction"`` (a parameter was derived to hit exactly this figure, or the model lacks the
  physics that could make it non-zero), ``"assumed"`` (it rests on an assumed input, such as an
  assumed load curve, more than on the servo), ``"not_evaluated"`` (no value);
- ``basis_reason``: the parameter or the missing physics, in words.

A mandatory requirement whose passing rows are all by construction does not count as a pass
(``compliance.requirements.verdict.overall_status``). docs/requirements.md, "Basis of a verdict".
"""

from __future__ import annotations

from compliance.model.parameters import used_by_model
from compliance.model.assumptions import SETTINGS
from compliance.requirements.verdict import Basis, Overall, Severity, Status
from compliance.results.summary import Qualifier

__all__ = ["limit_assumed", "requirement_basis", "row_basis", "verdict_qualifier"]

# metric -> the throttle whose conductance sets it (meter-out flow-control valves 2V2/2V3, seed 000)
_THROTTLE = {"opening_time": "flow_control.opening_conductance", "closing_time": "flow_control.closing_conductance"}
# effects through which the two speed settings could act on each other or a held position could move
_COUPLING_EFFECTS = ("supply_droop", "line_dynamics")
_LEAK_EFFECTS = ("internal_leakage", "external_leakage", "valve_offset")


def _load_of(op):
    """The operating point's constant load [N], 0 for none, None for a curve or the nominal load."""
    if op.load is None:
        return 0.0
    return op.load if isinstance(op.load, float) else None


def _stroke_metric(req, row) -> str | None:
    """Which stroke time a row's value is (opening_time / closing_time), for stroke_speed by its label."""
    if req.metric in _THROTTLE:
        return req.metric
    if req.metric == "stroke_speed" and row.get("which") in ("opening", "closing"):
        return f"{row['which']}_time"
    return None


def _derived(cfg, op, flow_control: bool, stroke_metric: str | None):
    """The derivation behind a stroke figure at ``op``, or None when the figure is a prediction."""
    if stroke_metric is None or not flow_control:
        return None
    key = _THROTTLE[stroke_metric]
    der = (cfg.assumptions.get(key) or {}).get("derived_for")
    if not der or der["metric"] != stroke_metric or cfg.sources.get(key) != "derived":
        return None
    load = _load_of(op)
    target = der["load"] or 0.0
    if load is None or abs(load - target) > 0.01 * max(abs(target), 1.0):
        return None
    return key, der


# the integral action is negligible when, at an error of the requirement's limit, it moves the valve command by less
# than this over a hold of HOLD_SPAN (our choice: 10 mV, a hundredth of a typical 1 V dead zone)
INTEGRAL_NEGLIGIBLE = 0.01  # V
HOLD_SPAN = 10.0  # s


def _limit_m(cfg, req) -> float:
    try:
        return float(req.resolved_limit(cfg.params["cylinder.stroke"])[-1])
    except (TypeError, ValueError, IndexError):
        return 0.0


def row_basis(cfg, reqset, req, row) -> tuple[Basis, str]:
    """(basis, basis_reason) of one verdict row (see the module docstring)."""
    if row.get("non_responding") and row.get("status") == Status.FAIL:
        return Basis.MODELLED, "the simulated step never responded: " + (row.get("reason") or "")
    if row.get("status") == Status.NOT_EVALUATED or row.get("value") is None:
        return Basis.NOT_EVALUATED, row.get("reason") or "no value"
    if req.source == "linear":
        return Basis.MODELLED, "linearised model at the operating point (compliance.linear)"
    op = reqset.operating_points[row["operating_point"]]
    proc = reqset.procedures.get(row["procedure"])
    fc = proc.settings.get("flow_control", True) if proc is not None and proc.kind == "full_stroke" else op.flow_control
    installed = cfg.flow_control_installed if fc is None else bool(fc)
    limiter_sets = (proc is not None and proc.kind == "full_stroke" and proc.settings.get("drive") == "governor"
                    and op.setpoint_limiter is not False and getattr(cfg, "setpoint_rate_limited", False))
    # with the governor's rate limiter setting the stroke rate the throttles are its backstop: the time is the
    # model's prediction of how the gate follows the limited set-point under this load, not the derivation's target
    found = None if limiter_sets else _derived(cfg, op, installed, _stroke_metric(req, row))
    if found:
        key, der = found
        return Basis.BY_CONSTRUCTION, (
            f"{key} ({cfg.sources[key]}) was derived so that the model gives {der['metric']} = {der['value']} at "
            f"{der['load_text']}: at this load the figure is the derivation's target, not evidence; measure the stroke")
    if req.metric == "cross_adjustment_change":
        on = [e for e in _COUPLING_EFFECTS if e in cfg.effects]
        picked = next((s for s in row.get("samples") or [] if s.get("label") == row.get("which")), None)
        if picked and (picked.get("detail") or {}).get("device") == "limiter":
            return Basis.MODELLED, (
                f"the governor's set-point rate limiter sets each direction's rate separately; the model changed "
                f"{picked['detail'].get('parameter')} and ran both strokes again under this load: the other direction's "
                "time is the model's prediction (nothing in the controller couples the two rates)")
        if not on:
            return Basis.BY_CONSTRUCTION, (
                "the model's supply is ideal (no supply_droop or line_dynamics effect) and each meter-out throttle sits on "
                "its own exhaust path: nothing couples the two directions, so the cross change is zero by construction")
    if req.metric in ("drift", "limit_cycle_amplitude"):
        on = [e for e in _LEAK_EFFECTS if e in cfg.effects]
        # an integral action winds the command up while stiction holds the gate, and can move it (hunting)
        integral = cfg.params.get("controller.ki", 0.0) * HOLD_SPAN * _limit_m(cfg, req) >= INTEGRAL_NEGLIGIBLE
        if not on and not integral:
            return Basis.BY_CONSTRUCTION, (
                "no leakage or valve offset is modelled (internal_leakage, external_leakage, valve_offset off) and the "
                "integral action is negligible (K_I x 10 s x the limit < 10 mV of command): nothing moves a held position "
                "once stiction holds it, so drift and hunting are zero by construction")
    if limit_assumed(req):
        return "assumed", (f"the limit is an assumed design target ({req.clause}), not a figure of a standard or of the "
                           "plant owner: the verdict holds against that target only")
    if op.load == "curve" and cfg.sources.get("load.curve") == "assumed":
        return Basis.ASSUMED, "the load at this point comes from the plant's assumed load curve (load.curve, source assumed)"
    tuned = [n for n in getattr(cfg, "commissioning", ()) if req.metric in SETTINGS[n].metrics]
    if tuned:
        return Basis.MODELLED, (
            f"simulated with the plant model; the plant file sets {', '.join(tuned)} on site by this test ([commissioning]), "
            "so the verdict says the adjustment reaches the limit, at the file's values and at each end of each range")
    return Basis.MODELLED, "simulated with the plant model at this operating point"


def requirement_basis(rows: list[dict]) -> Basis:
    """Basis of a requirement from its rows: that of its worst failure if it fails; for a pass, by
    construction when every passing row is, else modelled (assumed when no row is modelled)."""
    judged = [r for r in rows if r.get("status") in (Status.PASS, Status.FAIL)]
    if not judged:
        return Basis.NOT_EVALUATED
    fails = [r for r in judged if r["status"] == Status.FAIL]
    if fails:
        return Basis.MODELLED if any(r["basis"] == Basis.MODELLED for r in fails) else fails[0]["basis"]
    bases = {r["basis"] for r in judged}
    if bases == {Basis.BY_CONSTRUCTION}:
        return Basis.BY_CONSTRUCTION
    if Basis.MODELLED in bases:
        return Basis.MODELLED
    return Basis.ASSUMED if Basis.ASSUMED in bases else Basis.BY_CONSTRUCTION


def limit_assumed(req) -> bool:
    """Whether the requirement file says the limit is an assumed target (its clause or standard begins with
    "assumed"), not a figure of a standard or of the plant owner."""
    return any(str(t or "").strip().lower().startswith("assumed") for t in (req.clause, req.standard))


def verdict_qualifier(results: dict) -> str | None:
    """What an overall PASS rests on when it is not the plant's evidence against a real limit, else None.

    ``"against assumed targets"`` when a passing mandatory requirement's limit is assumed (verdict
    basis ``assumed`` for that reason), ``"on a mostly assumed model"`` when more than half of the
    parameters the selected model uses are assumed; both joined when both hold. One wording for the
    terminal summary, the results JSON (``summary.qualifier``) and page 1 of the report.
    """
    if (results.get("summary") or {}).get("status") != Overall.PASS:
        return None
    words = []
    if any(e.get("limit_assumed") and e.get("status") == Status.PASS and e.get("severity") == Severity.MANDATORY
           for e in results.get("requirements") or []):
        words.append(Qualifier.ASSUMED_TARGETS)
    plant = results.get("plant") or {}
    options = plant.get("options") or {}
    used = [p for p in plant.get("parameters") or [] if isinstance(p, dict) and used_by_model(str(p.get("key")), options)]
    if used and sum(1 for p in used if (p.get("source") or "assumed") == "assumed") > len(used) / 2:
        words.append(Qualifier.ASSUMED_MODEL)
    return ", ".join(words) or None

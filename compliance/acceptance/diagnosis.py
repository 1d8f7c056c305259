"""Why the machine does not do what the model said: the joint diagnosis of a site, and the refitted prediction.

When a measured figure disagrees with its prediction, the model lacks something the machine has.
The disagreements of the requirement where the machine fails what the model passes come first (the
machine has something the model lacks), then the other verdict changes, then the rest by size. The joint diagnosis (``diagnosis.servo.joint_recordings``:
every declared effect and the recalibration fitted with one parameter set over several
recordings, each with its own conditions) runs on the site's closed-loop recordings taken nearest
the conditions of the disagreeing tests (same load first, then the nearest position): a concealed
effect shows most there. The winner's fitted values make a refitted model; the disagreeing tests
are predicted again with it (``predict.site_prediction``: its band over the plant file's declared
ranges and the fitted values' own intervals, +/- K standard errors), which should now agree with
the measurement.

An open-loop test (a stroke, a hold with the valve at null) is not replayed inside the joint fit:
the joint engine replays closed-loop recordings only, so such a test is predicted again
plant-only over its window, which needs no controller.
"""

from __future__ import annotations

import math
import time

from compliance.acceptance.predict.agreement import agrees
from compliance.acceptance.measure.uncertainty import K
from compliance.acceptance.predict.site_prediction import predict_site
from compliance.effects import EFFECTS
from compliance.model.parameters import apply
from compliance.presentation.values import metric_text
from compliance.requirements.verdict import Status
from compliance.presentation.numbers import fmt_si

__all__ = ["MAX_RECORDINGS", "diagnose_site", "disagreements"]

MAX_RECORDINGS = 2  # closed-loop recordings the joint fit replays (each fit step replays every one of them)


def disagreements(entries: list) -> list:
    """Every disagreement between a measured figure and its prediction: the machine failing what the model passes
    first (the machine has something the model lacks), then the other verdict changes, then by size."""
    out = []
    for e in entries:
        p = e.get("prediction")
        if not p:
            continue
        changes = e["status"] in (Status.PASS, Status.FAIL) and p["status"] in (Status.PASS, Status.FAIL) and p["status"] != e["status"]
        for d in p["disagreeing"]:
            gap = min(abs(d["measured"] - d["low"]), abs(d["measured"] - d["high"])) / max(abs(d["measured"]), 1e-12)
            out.append({**d, "requirement": e["id"], "metric": e["measured_metric"], "measured_status": e["status"],
                        "predicted_status": p["status"], "verdict_changes": changes, "relative_gap": gap})
    def order(d):
        machine_fails = d["measured_status"] == Status.FAIL and d["predicted_status"] == Status.PASS
        return (not machine_fails, not d["verdict_changes"], -d["relative_gap"])

    return sorted(out, key=order)


def _closed_loop(prep) -> bool:
    t = prep.test
    return (not prep.problem and t.kind in ("step_series", "sine", "dead_band_staircase")
            and "reference" in prep.recording.frame.columns)


def _pick(prepared: list, targets: list) -> list:
    """The closed-loop recordings nearest the disagreeing tests' conditions (the targets themselves first when closed loop)."""
    by_name = {p.name: p for p in prepared}
    aims = [by_name[t] for t in targets if t in by_name]

    def distance(p):
        best = math.inf
        for a in aims:
            la = a.test.load if isinstance(a.test.load, (int, float)) else 0.0
            lp = p.test.load if isinstance(p.test.load, (int, float)) else 0.0
            xa = a.test.position if a.test.position is not None else 0.0
            xp = p.test.position if p.test.position is not None else 0.0
            best = min(best, abs(la - lp) / 1e3 + abs(xa - xp) * 1e2 - (10.0 if p.name == a.name else 0.0))
        return best

    pool = sorted((p for p in prepared if _closed_loop(p)), key=lambda p: (distance(p), p.name))
    return pool[:MAX_RECORDINGS]


def _refit_ranges(fit) -> list:
    """Each fitted value's own interval, +/- K standard errors within its bounds, as a range the prediction band moves."""
    out = []
    for fp, v, e in zip(fit.params, fit.values, fit.stderr):
        if fp.kind == "instrument" or not (e and math.isfinite(e) and e > 0):
            continue
        out.append((fp.path, {"low": max(fp.low, v - K * e), "high": min(fp.high, v + K * e)}))
    return out


def _physics(fit, winner: str) -> str:
    if winner in EFFECTS:
        eff = EFFECTS[winner]
        main = next((i for i, fp in enumerate(fit.params) if fp.kind == "effect"), 0)
        return eff.explanation.format(v=fmt_si(fit.values[main], fit.params[main].unit))
    return "the model's base parameters are off (recalibration)" if winner == "base" else winner.replace("_", " ")


def diagnose_site(cfg, prepared: list, cases: list, entries: list, *, workers=None, sine=None, effects=None,
                  recalibrate: bool = True) -> dict:
    """Diagnose the site's disagreements with the model (see the module docstring) -> the ``diagnosis`` of the site results."""
    from compliance.diagnosis.servo.joint_recordings import diagnose_joint

    t0 = time.perf_counter()
    found = disagreements(entries)
    if not found:
        return {"status": "not_needed", "text": "every judged test agrees with the model's prediction: nothing to diagnose",
                "disagreements": [], "recordings": [], "refit": []}
    first = found[0]["requirement"]
    deciding = [d for d in found if d["requirement"] == first]  # the requirement whose disagreement matters most
    targets = list(dict.fromkeys(d["run"] for d in deciding))
    chosen = _pick(prepared, targets)
    if not chosen:
        return {"status": "not_possible", "disagreements": found, "recordings": [], "refit": [],
                "text": "no closed-loop recording at this site: the joint diagnosis replays closed-loop tests"}
    joint = diagnose_joint(cfg, [(p.recording.frame, p.recording.meta) for p in chosen], jobs=workers, effects=effects,
                           recalibrate=recalibrate)
    data = joint.to_dict()
    out = {"status": joint.verdict, "winner": joint.winner, "reason": joint.reason, "disagreements": found,
           "targets": targets, "recordings": [p.name for p in chosen], "effects": data["effects"][:5],
           "before": data["before"], "after": data["after"], "refit": []}
    if joint.winner:
        fit = joint.fits[joint.winner]
        out["physics"] = _physics(fit, joint.winner)
        out["fitted"] = [{"name": fp.key, "value": v, "stderr": e, "unit": fp.unit} for fp, v, e in zip(fit.params, fit.values, fit.stderr)]
        fitted = apply(cfg, fit.params, fit.values, source="derived")
        by_name = {p.name: p for p in prepared}
        again = predict_site(fitted, [by_name[t] for t in targets], sine=sine, workers=workers,
                             extra_ranges=_refit_ranges(fit))
        for d in deciding:
            labels = [c.label for c in cases if c.recording == d["run"]]
            fig = again[d["run"]].figure("", labels.index(d["which"]), d["metric"]) if d["which"] in labels else None
            if fig is None:
                continue
            v, lo, hi = fig
            out["refit"].append({"requirement": d["requirement"], "run": d["run"], "which": d["which"], "metric": d["metric"],
                                 "measured": d["measured"], "u": d["u"], "predicted": v, "low": lo, "high": hi,
                                 "before": d["predicted"], "agree": agrees(d["measured"], d["u"] or 0.0, lo, hi)})
    out["text"] = _text(out)
    out["seconds"] = time.perf_counter() - t0
    return out


def _v(value, metric: str, digits: int = 3) -> str:
    return metric_text(value, metric, digits, unicode=False)


def _text(d: dict) -> str:
    parts = []
    for x in d["disagreements"][:3]:
        m = x["metric"]
        parts.append(f"{x['run']} ({x['requirement']}): measured {_v(x['measured'], m)} +/- {_v(x['u'], m, 2)}, predicted "
                     f"{_v(x['predicted'], m)} [{_v(x['low'], m)} .. {_v(x['high'], m)}]")
    text = "The machine and the model disagree on " + "; ".join(parts) + "."
    if d.get("winner"):
        text += (f" The joint diagnosis of {', '.join(d['recordings'])} finds the model lacks: {d['physics']} "
                 f"({d['status'].replace('_', ' ')}).")
        for r in d["refit"]:
            m = r["metric"]
            text += (f" Refitted, the model predicts {_v(r['predicted'], m)} [{_v(r['low'], m)} .. {_v(r['high'], m)}] for "
                     f"{r['run']} against {_v(r['measured'], m)} measured: {'agrees' if r['agree'] else 'still disagrees'}.")
    else:
        text += f" The joint diagnosis finds no explanation: {d.get('reason')}"
    return text

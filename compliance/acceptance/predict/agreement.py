"""Measured beside predicted: does the machine do what the model said, within the band and the measurement uncertainty?

For every judged case the predicted figure of the same test (``predict.site_prediction``) is set
beside the measured one. They *agree* when the measured interval [v - U, v + U] meets the predicted
band [low, high]; otherwise the test is named with both figures. The model's own verdict of a row
and of the requirement is judged the same way as the measured one, with the band in place of the
measurement uncertainty (a band that straddles the limit makes it UNCERTAIN).
"""

from __future__ import annotations

from compliance.acceptance.judge.entries import requirement_status
from compliance.acceptance.judge.rows import with_uncertainty
from compliance.acceptance.measure.uncertainty import Measured
from compliance.requirements.verdict import Status

__all__ = ["attach_predictions", "agrees"]


def agrees(value: float, u: float, low: float, high: float) -> bool:
    """The measured interval [value - u, value + u] meets the predicted band [low, high]."""
    return value + u >= low and value - u <= high


def _predicted_status(entry: dict, v: float, low: float, high: float) -> Status:
    """The model's verdict of a figure with its band: UNCERTAIN when the band straddles the limit."""
    if entry["limit"] is None:
        return Status.OPEN
    statuses = {with_uncertainty(Measured(x), entry["comparator"], entry["limit"])[1] for x in (v, low, high)}
    return statuses.pop() if len(statuses) == 1 else Status.UNCERTAIN


def _row_prediction(entry: dict, row: dict, lookup) -> dict | None:
    out, disagree = None, []
    for s in row.get("samples", []):
        fig = lookup(s["recording"], s["label"], entry["measured_metric"])
        if fig is None or s["value"] is None:
            continue
        v, lo, hi = fig
        ok = agrees(s["value"], s["u"] or 0.0, lo, hi)
        s["predicted"] = {"value": v, "low": lo, "high": hi, "agree": ok}
        if s["eligible"] and not ok:
            disagree.append({"run": s["recording"], "which": s["label"], "measured": s["value"], "u": s["u"],
                             "predicted": v, "low": lo, "high": hi})
        if s["label"] == row.get("which"):
            out = {"value": v, "low": lo, "high": hi, "agree": ok, "status": _predicted_status(entry, v, lo, hi)}
    if out is None and row.get("status") in (Status.PASS, Status.FAIL, Status.UNCERTAIN):
        return {"value": None, "low": None, "high": None, "agree": None, "status": Status.NOT_EVALUATED,
                "disagreeing": disagree, "reason": "no prediction of this test"}
    if out is not None:
        out["disagreeing"] = disagree
    return out


def attach_predictions(entries: list, cases: dict, predicted: dict, options_key) -> None:
    """Put the prediction beside every row and requirement of ``entries`` (in place).

    Parameters
    ----------
    entries : list of dict
        The site's requirement entries (``judge.entries``).
    cases : dict
        Options key -> measured cases (the same order as the predicted ones, per recording).
    predicted : dict
        Recording -> ``Predicted``.
    options_key : callable
        Requirement id -> the options key its rows were measured with.
    """
    for e in entries:
        key = options_key(e["id"])
        index = {}
        for c in cases.get(key, cases[""]):
            labels = index.setdefault(c.recording, {})
            labels[c.label] = len(labels)

        def lookup(rec, label, metric, _index=index, _key=key):
            p = predicted.get(rec)
            i = _index.get(rec, {}).get(label)
            return None if p is None or i is None else p.figure(_key, i, metric)

        preds = []
        for row in e.get("rows", []):
            row["prediction"] = _row_prediction(e, row, lookup)
            if row["prediction"] is not None:
                preds.append((row, row["prediction"]))
        if not preds:
            e["prediction"] = None
            continue
        status = requirement_status([{"status": p["status"]} for _, p in preds], e["limit"])
        worst_row = next((r for r, _ in preds if e.get("worst") and r.get("which") == e["worst"].get("which")
                          and r.get("run") == e["worst"].get("run")), preds[0][0])
        wp = worst_row["prediction"]
        disagreeing = [d for _, p in preds for d in p.get("disagreeing", [])]
        e["prediction"] = {"value": wp["value"], "low": wp["low"], "high": wp["high"], "status": status,
                           "agree": not disagreeing and all(p["agree"] is not False for _, p in preds),
                           "disagreeing": disagreeing, "verdicts_agree": status == e["status"]}

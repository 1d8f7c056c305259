"""The site results: the schema ``govcheck-site/1`` that ``govcheck accept --json`` writes and the report and ``gate`` read.

The ``requirements[]`` entries are ``check``'s (``id``, ``status``, ``worst``, ``rows`` - one per
recording x procedure x operating point, ``run`` = the recording - with basis ``measured``), each
measured value with its uncertainty ``u`` and the prediction beside it; ``site`` describes the
recordings (the test as run, its instruments, its departures, its cases, a thinned trace with the
predicted one); ``summary`` is ``check``'s with the coverage and the agreement with the model.
docs/acceptance.md gives every key.
"""

from __future__ import annotations

import datetime as _dt
import hashlib

from compliance.campaign.results_files import SITE_SCHEMA
from compliance.campaign.run import plant_section, summary_section, versions_section
from compliance.files.display import display_path
from compliance.requirements.verdict import Overall, Severity, Status

__all__ = ["SITE_SCHEMA", "TRACE_POINTS", "site_results"]

TRACE_POINTS = 1500  # samples of a recorded trace kept for the report's figures


def _digest(paths) -> str:
    h = hashlib.sha256()
    for p in paths:
        h.update(p.name.encode())
        h.update(hashlib.sha256(p.read_bytes()).digest())
    return h.hexdigest()


def _trace(prep, predicted) -> dict:
    c = prep.cond
    step = max(1, c.time.size // TRACE_POINTS)
    out = {"time": c.time[::step].tolist(), "position": c.raw[::step].tolist()}
    for col in ("reference", "valve_command"):
        if c.column(col) is not None:
            out[col] = c.column(col)[::step].tolist()
    if predicted is not None and predicted.trace is not None:
        out["predicted"] = {"time": predicted.trace["time"], "position": predicted.trace["position"]}
    return out


def _recording(prep, cases, predicted) -> dict:
    from compliance.recordings.metadata import sidecar_path

    rec, t = prep.recording, prep.test
    side = sidecar_path(rec.path)
    own = [c for c in cases if c.recording == prep.name]
    return {
        "name": prep.name, "path": display_path(str(rec.path)), "format": rec.meta.get("format"),
        "digest": hashlib.sha256(rec.path.read_bytes()).hexdigest(),
        "sidecar": display_path(str(side)) if side.is_file() else None,
        "test": {"kind": t.kind, "source": t.source, "load": t.load, "flow_control": t.flow_control, "position": t.position,
                 "supply_pressure": t.supply_pressure, "settings": t.settings, "notes": list(t.notes),
                 "loop": (rec.meta.get("test") or {}).get("loop")},
        "problem": prep.problem,
        "conditions": rec.meta.get("conditions"), "controller": rec.meta.get("controller"),
        "channels": [c for c in rec.frame.columns if c != "time"],
        "logger": {k: v for k, v in (rec.meta.get("logger") or {}).items()},
        "instruments": prep.cond.instruments(),
        "departures": sorted({d for c in own for d in c.departures}),
        "cases": [c.as_dict() for c in own],
        "prediction": None if predicted is None else {"error": predicted.error},
        "trace": _trace(prep, predicted),
    }


def _agreement(entries: list) -> dict:
    judged = [e for e in entries if e.get("prediction")]
    disagree = [e["id"] for e in judged if e["prediction"]["agree"] is False]
    differ = [e["id"] for e in judged if e["status"] in (Status.PASS, Status.FAIL, Status.UNCERTAIN)
              and not e["prediction"]["verdicts_agree"]]
    tests = sorted({d["run"] for e in judged for d in e["prediction"]["disagreeing"]})
    return {"agree": [e["id"] for e in judged if e["prediction"]["agree"]], "disagree": disagree,
            "verdicts_differ": differ, "tests": tests}


def _summary(entries: list) -> dict:
    s = summary_section(entries, [])
    partial = [e["id"] for e in entries if e["status"] in (Status.PASS, Status.UNCERTAIN, Status.FAIL)
               and not e["coverage"]["complete"]]
    s["partial"] = partial
    mandatory_partial = [e["id"] for e in entries if e["id"] in partial and e["severity"] == Severity.MANDATORY
                         and e["status"] == Status.PASS]
    if s["status"] == Overall.PASS and mandatory_partial:
        s["status"] = Overall.INCOMPLETE
        s["notes"].append("a mandatory requirement passes on part of its cases only: " + ", ".join(mandatory_partial))
    s["agreement"] = _agreement(entries)
    s["qualifier"] = None
    return s


def site_results(site, prepared: list, cases: list, entries: list, predicted: dict, cfg, reqset, *,
                 command_line: str | None = None, diagnosis: dict | None = None, timing: dict | None = None) -> dict:
    """The site results dict (schema ``govcheck-site/1``; see the module docstring)."""
    from pathlib import Path

    from compliance.recordings.metadata import sidecar_path

    files = []
    for p in sorted(prep.recording.path for prep in prepared):
        files += [p] + ([sidecar_path(p)] if sidecar_path(p).is_file() else [])
    return {
        "schema": SITE_SCHEMA,
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "command_line": command_line,
        "versions": versions_section(),
        "site": {"name": Path(site).name, "path": display_path(str(site)), "digest": _digest(files),
                 "recordings": [_recording(p, cases, predicted.get(p.name)) for p in prepared]},
        "plant": plant_section(cfg),
        "requirement_set": reqset.as_dict(),
        "summary": _summary(entries),
        "requirements": entries,
        "diagnosis": diagnosis,
        "timing": timing or {},
    }

"""The recordings a plant file names, replayed with the model as ``govcheck validate`` does, as model evidence.

Each recording is read (its sidecar gives the test conditions), replayed in the modes it allows and
judged window by window against the validation limits (``compliance.validation``; a settings file
may give the grid code's limits). The position's steady windows are evidence for the settled
figures (positioning error, drift, dead band), its transient windows for the dynamic ones (time
constant, settling, speeds, stroke times, tracking); a failing window of another signal says the
model's internals differ without naming a verdict.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

from compliance.files.display import display_path

__all__ = ["BEARS_ON_WINDOWS", "recording_source"]

# the govcheck metrics a window of the recorded position is evidence for, by window kind (govcheck's reading)
BEARS_ON_WINDOWS = {
    "steady": ("max_positioning_error", "drift", "limit_cycle_amplitude", "dead_band"),
    "transient": ("time_constant", "dead_time", "settling_time", "overshoot", "tracking_max_error", "max_speed",
                  "max_opening_speed", "max_closing_speed", "opening_time", "closing_time", "stroke_speed"),
}


def recording_source(cfg, entry) -> dict:
    """Replay one recording named in ``[model_evidence]`` and summarise its agreement (docs/results-schema.md)."""
    from compliance.recordings.reader import read_recording
    from compliance.validation.validate import load_settings, validate

    settings = load_settings(entry["settings"]) if entry.get("settings") else None
    df, meta = read_recording(entry["path"], entry.get("column_map"), required=("time", "position"))
    result = validate(cfg, df, meta, settings)
    modes, bears = {}, set()
    for mode, m in result["modes"].items():
        failed = [r for r in m["window_metrics"] if not r["pass"]]
        for r in failed:
            if r["signal"] == "position":
                bears |= set(BEARS_ON_WINDOWS.get(r["kind"], ()))
        modes[mode] = {"pass": m["pass"], "windows": len(m["window_metrics"]),
                       "failed_windows": [{"window": r["window"], "kind": r["kind"], "signal": r["signal"],
                                           "failed": r["failed"]} for r in failed],
                       "fits": {s: f.get("fit_percent") for s, f in m["fits"].items()}}
    ok = bool(result["summary"]["pass"])
    return {"kind": "recording", "path": display_path(entry["path"]),
            "digest": hashlib.sha256(Path(entry["path"]).read_bytes()).hexdigest(), "note": entry.get("note"),
            "description": result["recording"].get("description"), "independent": True,
            "agreement": "agrees" if ok else "contradicts", "modes": modes, "bears_on": sorted(bears),
            "warnings": list(result.get("warnings") or []),
            "command": f"govcheck validate {display_path(cfg.path) or cfg.name} {display_path(entry['path'])}"}

"""Optional ``[model_evidence]`` table of a plant configuration: the measurements its model answers to.

A check carries the model's agreement with each source named here beside its verdicts
(``compliance.evidence``; results key ``model_evidence``, docs/results-schema.md):

    [model_evidence]
    paper = "plant-a"        # the plant paper's measured figures (what `govcheck reproduce` compares)
    recordings = [           # recordings of this servo, replayed as `govcheck validate` does
      { path = "runs/steps-2024-05.csv.gz", settings = "val-limits.toml", column_map = "bench.toml", note = "..." },
    ]

Paths are relative to the plant file's folder. None of it enters the physics. The names of the
papers govcheck holds a table for are checked where the comparison lives (``compliance.evidence``).
"""

from __future__ import annotations

from pathlib import Path
from types import MappingProxyType

from compliance.errors import InputError

__all__ = ["RECORDING_FIELDS", "parse_model_evidence"]

RECORDING_FIELDS = ("path", "settings", "column_map", "note")


def _text(v, where: str) -> str:
    if not isinstance(v, str) or not v.strip():
        raise InputError(f"{where}: expected a non-empty string")
    return v.strip()


def _resolve(text: str, base: Path | None) -> str:
    p = Path(text)
    return str(p if p.is_absolute() or base is None else base / p)


def parse_model_evidence(raw, where: str, plant_path: str | None) -> MappingProxyType:
    """Validate a ``[model_evidence]`` table -> read-only ``{"paper": str or None, "recordings": (dict, ...)}``.

    Recording paths (and their settings and column-map files) are resolved against the plant
    file's folder and must exist.

    Raises
    ------
    InputError
        An unknown key, a value of the wrong type, or a file that does not exist (named with its key).
    """
    if raw is None:
        return MappingProxyType({"paper": None, "recordings": ()})
    if not isinstance(raw, dict):
        raise InputError(f"{where}: [model_evidence] must be a table")
    unknown = set(raw) - {"paper", "recordings"}
    if unknown:
        raise InputError(f"{where}: model_evidence.{sorted(unknown)[0]}: unknown key (expected paper, recordings)")
    paper = _text(raw["paper"], f"{where}: model_evidence.paper") if "paper" in raw else None
    recs = raw.get("recordings", [])
    if not isinstance(recs, list):
        raise InputError(f"{where}: model_evidence.recordings: expected a list of {{ path = \"...\" }} tables")
    base = Path(plant_path).parent if plant_path else None
    out = []
    for i, r in enumerate(recs):
        kw = f"{where}: model_evidence.recordings[{i}]"
        if not isinstance(r, dict) or "path" not in r:
            raise InputError(f"{kw}: expected {{ path = \"recording.csv\" }} (optional settings, column_map, note)")
        bad = set(r) - set(RECORDING_FIELDS)
        if bad:
            raise InputError(f"{kw}.{sorted(bad)[0]}: unknown key (expected {', '.join(RECORDING_FIELDS)})")
        entry = {k: _text(r[k], f"{kw}.{k}") for k in RECORDING_FIELDS if k in r}
        for k in ("path", "settings"):
            if k in entry:
                entry[k] = _resolve(entry[k], base)
                if not Path(entry[k]).is_file():
                    raise InputError(f"{kw}.{k}: {entry[k]}: file not found")
        if "column_map" in entry and Path(_resolve(entry["column_map"], base)).is_file():
            entry["column_map"] = _resolve(entry["column_map"], base)  # else a shipped column map's name
        out.append(MappingProxyType(entry))
    return MappingProxyType({"paper": paper, "recordings": tuple(out)})

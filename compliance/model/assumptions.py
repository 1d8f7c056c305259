"""What a plant file says about how sure it is: plausible ranges of assumed values, and derived targets.

A parameter entry may carry, beside ``value``, ``source`` and ``note``:

- ``range = ["300 N", "540 N"]`` with ``range_note = "why"``: the plausible span of a value that
  is assumed (or derived, or read off a figure); the verdicts' uncertainty bands propagate it
  (``compliance.campaign.uncertainty``);
- ``derived_for = { metric = "opening_time", value = "5.0 s", load = "5.7 kN" }``: the value was
  derived (tuned) so that the model gives that figure under that load, so the figure at that load
  is known by construction, not as evidence (``compliance.campaign.basis``).

Both are read here with units, at the edge, and kept on the configuration as plain data. So is the
optional ``[model_evidence]`` table, the measurements the model answers to (a check carries its
agreement with each beside the verdicts, ``compliance.model_evidence``; docs/results-schema.md):

    [model_evidence]
    paper = "plant-a"        # the plant paper's measured figures (what `govcheck reproduce` compares)
    recordings = [           # recordings of this servo, replayed as `govcheck validate` does
      { path = "runs/steps.csv.gz", settings = "val-limits.toml", column_map = "bench.toml", note = "..." },
    ]

Its paths are relative to the plant file's folder and must exist; the papers govcheck holds a
table for are checked where the comparison lives. And so is the optional ``[commissioning]`` table,
the governor settings made on site from measurements (the last section of this module).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Any

from compliance.errors import InputError, did_you_mean
from compliance.model.parameters import BASE_BY_KEY
from compliance.units import parse_quantity

__all__ = ["EFFECT_ENTRY_FIELDS", "ENTRY_FIELDS", "ORDER", "RECORDING_FIELDS", "SETTINGS", "Setting", "check_effect_entry",
           "commissioning_toml", "parse_commissioning", "parse_model_evidence", "read_assumptions"]

# the fields a parameter entry may hold (the loader refuses any other)
ENTRY_FIELDS = ("value", "source", "note", "range", "range_note", "derived_for")
# the fields an effect parameter's entry may hold: the uncertainty bands move base parameters only
EFFECT_ENTRY_FIELDS = ("value", "source", "note")


def check_effect_entry(entry: dict, where: str) -> None:
    """An ``[effects.NAME]`` parameter given as a table holds only value, source and note.

    A ``range`` there would be read and then never used (the bands move the base parameters'
    ranges), so it is refused at load rather than accepted and ignored.

    Raises
    ------
    InputError
        A range / derived_for on an effect parameter, an unknown field, or no value.
    """
    for key in entry:
        if key in ("range", "range_note", "derived_for"):
            raise InputError(f"{where}.{key}: ranges and derivation targets are read on base parameters only (the "
                             "uncertainty bands move those); an effect parameter's range would be ignored, so it is "
                             "refused - give the value alone")
        if key not in EFFECT_ENTRY_FIELDS:
            raise InputError(f"{where}.{key}: unknown field (an effect parameter's entry holds {', '.join(EFFECT_ENTRY_FIELDS)})")
    if "value" not in entry:
        raise InputError(f"{where}: missing 'value'")


def _range(entry: dict, key: str, where: str, value: float, atmosphere: float) -> dict:
    spec = BASE_BY_KEY[key]
    raw = entry["range"]
    if not isinstance(raw, list) or len(raw) != 2:
        raise InputError(f"{where}.range: expected [low, high] with units, e.g. [\"300 N\", \"540 N\"]")
    if spec.unit in ("number", ""):
        lo, hi = (_pure_number(v, f"{where}.range") for v in raw)
    else:
        lo, hi = (parse_quantity(v, spec.unit, f"{where}.range", pressure=spec.pressure, atmosphere=atmosphere) for v in raw)
    if lo > hi:
        raise InputError(f"{where}.range: low {lo:g} is above high {hi:g} {spec.unit}; write the range as [low, high]")
    if not lo <= value <= hi:
        raise InputError(f"{where}.range: [{lo:g}, {hi:g}] {spec.unit} must contain the value {value:g}")
    if lo == hi:
        raise InputError(f"{where}.range: low and high are equal; leave the range out for an exact value")
    note = entry.get("range_note")
    if not isinstance(note, str) or not note.strip():
        raise InputError(f"{where}.range_note: missing; say why the value may lie anywhere in the range")
    return {"low": lo, "high": hi, "note": note.strip()}


def _pure_number(v, where: str) -> float:
    """One end of a range of a unit-less parameter: a number (or a text of one), never a quantity with a unit."""
    if isinstance(v, bool):
        raise InputError(f"{where}: {v!r} is not a number")
    if isinstance(v, (int, float)):
        return float(v)
    try:
        return float(str(v))
    except ValueError:
        pass
    try:  # a dimensionless quantity ("52.8 %") is a number too
        return parse_quantity(str(v), "", where)
    except InputError:
        raise InputError(f"{where}: {v!r}; this parameter is a pure number, so its range is two plain numbers "
                         "(e.g. [0.2, 0.4]), without a unit") from None


def _derived_for(entry: dict, where: str) -> dict:
    raw = entry["derived_for"]
    if not isinstance(raw, dict) or not isinstance(raw.get("metric"), str):
        raise InputError(f"{where}.derived_for: expected {{ metric = \"opening_time\", value = \"5.0 s\", load = \"5.7 kN\" }}")
    unknown = set(raw) - {"metric", "value", "load"}
    if unknown:
        raise InputError(f"{where}.derived_for.{sorted(unknown)[0]}: unknown field (expected metric, value, load)")
    load = raw.get("load")
    return {"metric": raw["metric"], "value": str(raw.get("value", "")),
            "load": None if load in (None, "none") else parse_quantity(load, "N", f"{where}.derived_for.load"),
            "load_text": str(load or "none")}


def read_assumptions(data: dict[str, Any], where: str, params: dict, atmosphere: float) -> dict:
    """Ranges and derivation targets of the base parameters a plant file gives (SI).

    Parameters
    ----------
    data : dict
        The parsed plant file.
    where : str
        The file, for messages.
    params : dict
        The parameters already read (dotted key -> SI value).
    atmosphere : float
        Atmospheric pressure [Pa], for gauge pressures in ranges.

    Returns
    -------
    dict
        Dotted key -> ``{"range": {"low", "high", "note"} or None, "derived_for": {...} or None}``,
        only for parameters that give either.

    Raises
    ------
    InputError
        A range without units or reason, not containing the value, or a malformed ``derived_for``.
    """
    out: dict[str, dict] = {}
    for key, spec in BASE_BY_KEY.items():
        section, name = key.split(".", 1)
        entry = (data.get(section) or {}).get(name) if isinstance(data.get(section), dict) else None
        if not isinstance(entry, dict) or not ({"range", "derived_for"} & set(entry)):
            continue
        kw = f"{where}: {key}"
        rng = _range(entry, key, kw, params[key], atmosphere) if "range" in entry else None
        der = _derived_for(entry, kw) if "derived_for" in entry else None
        out[key] = {"range": rng, "derived_for": der}
    return out


# --------------------------------------------------------------------------- [model_evidence]
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


# --------------------------------------------------------------------------- [commissioning]
# Commissioning settings: the governor adjustments a plant file says are set on site, from measurements.
#
# A governor's opening and closing times are adjustments of the governor, not properties of its
# hardware (IEC 61362:2024 specifies them as adjustable quantities; IEEE Std 125-2007, 5.2.6: adjustable
# independently), and the position loop's gain is a tuning parameter of the actuator (IEEE Std
# 1207-2011 treats the servomotor's gain so); that it is set on site from the measured time constant is
# govcheck's reading. A design whose file declares these settings is judged as a test engineer judges
# the commissioned machine: at each end of each declared range (a valve that opens fully at 3 V instead
# of 4 V, a load a quarter higher) the settings are made again by the measurement the commissioning
# engineer makes, and only then are the acceptance tests run (``campaign.commissioning``). Which
# settings a plant file declares is its own statement; the rules that make them are govcheck's
# (docs/requirements.md, "Commissioned settings").
#
# The plant file's table::
#
#     [commissioning]
#     settings = ["limiter_rates", "loop_gain"]
#     note = "set on site by timing the strokes and measuring the time constant"
#
# A changed design keeps the table: the settings are the design's adjustments, not measurements.


@dataclass(frozen=True)
class Setting:
    """One adjustment made at commissioning: its parameters and the measurement that sets them."""

    name: str
    meaning: str
    parameters: tuple[str, ...]
    measured_by: str
    metrics: tuple[str, ...]  # the metrics whose tests set it (their verdicts say the adjustment reaches the limit)


SETTINGS = {s.name: s for s in (
    Setting("limiter_rates", "the set-point rate limiter's opening and closing rates, one per direction",
            ("controller.setpoint_opening_rate", "controller.setpoint_closing_rate"),
            "the requirement file's opening and closing times and stroke rate, timed on its full strokes",
            ("opening_time", "closing_time", "stroke_speed")),
    Setting("loop_gain", "the position loop's gain K_P (K_I, K_D and the dead-zone inverse's width in proportion) "
            "and the closing side's slope",
            ("controller.kp", "controller.ki", "controller.kd", "controller.compensation_width",
             "controller.compensation_slope_negative"),
            "the requirement file's time-constant steps, with the limiting devices not acting", ("time_constant",)),
)}
# the order commissioning makes them in: the gain first, since the stroke's lag behind the limiter depends on it
ORDER = ("loop_gain", "limiter_rates")


def parse_commissioning(raw, where: str) -> tuple[str, ...]:
    """Validate a ``[commissioning]`` table -> the declared setting names, in commissioning order.

    Raises
    ------
    InputError
        Not a table, an unknown key, or a setting name govcheck does not know (named with the file).
    """
    if raw is None:
        return ()
    if not isinstance(raw, dict):
        raise InputError(f"{where}: [commissioning] must be a table (settings = [\"limiter_rates\", \"loop_gain\"])")
    unknown = set(raw) - {"settings", "note"}
    if unknown:
        raise InputError(f"{where}: commissioning.{sorted(unknown)[0]}: unknown key (expected settings, note)")
    names = raw.get("settings", [])
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        raise InputError(f"{where}: commissioning.settings: expected a list of setting names "
                         f"({', '.join(SETTINGS)})")
    for n in names:
        if n not in SETTINGS:
            raise InputError(f"{where}: commissioning.settings: '{n}' is not a setting govcheck can commission "
                             f"(expected {', '.join(SETTINGS)}){did_you_mean(n, list(SETTINGS))}")
    if "note" in raw and not isinstance(raw["note"], str):
        raise InputError(f"{where}: commissioning.note: expected a string")
    return tuple(n for n in ORDER if n in names)


def commissioning_toml(settings) -> list[str]:
    """The ``[commissioning]`` table of a saved configuration (empty when nothing is commissioned)."""
    if not settings:
        return []
    return ["[commissioning]", "settings = [" + ", ".join(f'"{s}"' for s in settings) + "]",
            'note = "set on site by the measurement each setting names (govcheck: docs/requirements.md, '
            '\'Commissioned settings\')"', ""]

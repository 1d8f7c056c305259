"""The fields of a plant configuration file, each read and checked with its unit at the edge.

:func:`compliance.model.config.plant_from_dict` composes these: base parameters and options per
section, the defaults of what a file leaves out, the load curve, and the effects switched on.
Every problem raises :class:`InputError` naming the file and the key path.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from compliance.effects import EFFECTS
from compliance.errors import InputError, did_you_mean
from compliance.model.parameters import BASE_BY_KEY, BASE_PARAMS, OPTION_DEFAULTS, OPTIONS, SOURCES

CALIBRATED_PREFIX = "calibrated to "  # source of a value fitted by a calibration (papers/calibration_table.py)
from compliance.model.toml_file import check_table
from compliance.model.assumptions import ENTRY_FIELDS, check_effect_entry
from compliance.units import ATMOSPHERE_PA, convert_array, parse_quantity

SECTIONS = sorted({k.split(".")[0] for k in BASE_BY_KEY} | {k.split(".")[0] for k in OPTIONS})


def option_value(entry, key: str, where: str) -> str:
    """Read an option (``friction.model = "stribeck"``; TOML booleans become "true"/"false")."""
    val = str(entry).lower() if isinstance(entry, bool) else entry
    if not isinstance(val, str) or val not in OPTIONS[key]:
        raise InputError(f"{where}: '{entry}' is not one of {', '.join(OPTIONS[key])}{did_you_mean(str(entry), OPTIONS[key])}")
    return val


def param_value(entry, key: str, where: str, atmosphere: float) -> tuple[float, str]:
    """Read ``key = "125 mm"`` or ``key = {value = "125 mm", source = "paper"}``.

    Returns
    -------
    tuple
        (SI value, source); gauge pressures are made absolute with ``atmosphere`` [Pa].
    """
    spec = BASE_BY_KEY[key]
    source = "user"
    if isinstance(entry, dict):
        unknown = set(entry) - set(ENTRY_FIELDS)
        if unknown:
            u = sorted(unknown)[0]
            raise InputError(f"{where}.{u}: unknown field{did_you_mean(u, ENTRY_FIELDS)} (expected {', '.join(ENTRY_FIELDS)})")
        if "value" not in entry:
            raise InputError(f"{where}: missing 'value'")
        source = entry.get("source", "user")
        # a calibrated value names what it was calibrated to: "calibrated to <figures> ..."
        if source not in SOURCES and not (isinstance(source, str) and source.startswith(CALIBRATED_PREFIX)):
            raise InputError(f"{where}.source: '{source}' is not one of {', '.join(SOURCES)} "
                             f"nor '{CALIBRATED_PREFIX}<what it was fitted to>'")
        entry = entry["value"]
    if spec.unit == "number":
        if isinstance(entry, bool) or not isinstance(entry, (int, float)):
            raise InputError(f"{where}: expected a bare number in SI base units")
        value = float(entry)
    else:
        value = parse_quantity(entry, spec.unit, where, pressure=spec.pressure, atmosphere=atmosphere)
    if not math.isfinite(value):
        raise InputError(f"{where}: value is not finite")
    low, high = spec.bounds
    bad = value < low or value > high or (spec.low_open and value <= low)
    if bad:
        lo = f"> {low:g}" if spec.low_open else f">= {low:g}"
        raise InputError(f"{where}: {value:g} {spec.unit} is not physical; expected {lo} and <= {high:g} ({spec.meaning})")
    return value, source


def array_field(entry, where: str, si_unit: str, stroke: float | None = None) -> np.ndarray:
    """Read ``{ values = [...], unit = "..." }`` in SI (``%``/``fraction`` of ``stroke`` for positions)."""
    if not isinstance(entry, dict) or "values" not in entry or "unit" not in entry:
        raise InputError(f"{where}: expected {{ values = [...], unit = \"...\" }}")
    vals = entry["values"]
    if not isinstance(vals, list) or not vals or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in vals):
        raise InputError(f"{where}.values: expected a non-empty list of numbers")
    unit = entry["unit"]
    if stroke is not None and unit in ("%", "percent", "% stroke", "fraction"):
        scale = stroke / 100.0 if unit != "fraction" else stroke
        return np.array(vals, dtype=float) * scale
    return convert_array(np.array(vals, dtype=float), unit, si_unit, where)


def atmosphere_of(data: dict[str, Any], where: str) -> float:
    """air.atmospheric_pressure [Pa abs], read first: gauge pressures convert with it."""
    air = data.get("air", {})
    if isinstance(air, dict) and "atmospheric_pressure" in air:
        return param_value(air["atmospheric_pressure"], "air.atmospheric_pressure", f"{where}: air.atmospheric_pressure", ATMOSPHERE_PA)[0]
    return ATMOSPHERE_PA  # until a file gives air.atmospheric_pressure


def section_values(data: dict[str, Any], where: str):
    """Base parameters and options of every ``[section]``, the missing ones from their defaults.

    Returns
    -------
    tuple
        (params {key: SI float}, sources {key: source}, options {key: str}, raw ``load.curve`` or None).
    """
    atmosphere = atmosphere_of(data, where)
    params: dict[str, float] = {}
    sources: dict[str, str] = {}
    options = dict(OPTION_DEFAULTS)
    load_curve_raw = None
    for section in SECTIONS:
        table = data.get(section)
        if table is None:
            continue
        if not isinstance(table, dict):
            raise InputError(f"{where}: [{section}] must be a table")
        for k, entry in table.items():
            key = f"{section}.{k}"
            kw = f"{where}: {key}"
            if key == "load.curve":
                load_curve_raw = entry
            elif key in OPTIONS:
                options[key] = option_value(entry, key, kw)
            elif key in BASE_BY_KEY:
                params[key], sources[key] = param_value(entry, key, kw, atmosphere)
            else:
                choices = [b.name.split(".", 1)[1] for b in BASE_PARAMS if b.name.startswith(section + ".")]
                choices += [o.split(".", 1)[1] for o in OPTIONS if o.startswith(section + ".")]
                raise InputError(f"{kw}: unknown key '{k}' in [{section}]{did_you_mean(k, choices)}")
    for spec in BASE_PARAMS:
        if spec.name not in params:
            if spec.default is None:
                raise InputError(f"{where}: missing value {spec.name} ({spec.meaning}, unit {spec.unit})")
            params[spec.name] = float(spec.default)
            sources[spec.name] = "assumed"
    return params, sources, options, load_curve_raw


def load_curve_field(raw, where: str, stroke: float) -> tuple[np.ndarray, np.ndarray]:
    """Read ``[load.curve]``: (position [m], closing force [N]), positions strictly increasing."""
    kw = f"{where}: load.curve"
    check_table(raw, kw, ("position", "force", "source", "note"), word="field", expected="a table with position and force")
    if "position" not in raw or "force" not in raw:
        raise InputError(f"{kw}: needs both 'position' and 'force'")
    xs = array_field(raw["position"], f"{kw}.position", "m", stroke)
    fs = array_field(raw["force"], f"{kw}.force", "N")
    if xs.shape != fs.shape:
        raise InputError(f"{kw}: position has {xs.size} values but force has {fs.size}")
    if np.any(np.diff(xs) <= 0):
        raise InputError(f"{kw}.position: values must be strictly increasing")
    return xs, fs


def effect_values(data: dict[str, Any], where: str) -> dict[str, dict[str, float]]:
    """The ``[effects.NAME]`` tables switched on, each merged with its declared defaults (SI)."""
    effects: dict[str, dict[str, float]] = {}
    eff_raw = data.get("effects", {})
    if not isinstance(eff_raw, dict):
        raise InputError(f"{where}: [effects] must be a table of [effects.NAME] tables")
    for ename, table in eff_raw.items():
        kw = f"{where}: effects.{ename}"
        if ename not in EFFECTS:
            raise InputError(f"{kw}: effect '{ename}' is not known{did_you_mean(ename, EFFECTS)} (known: {', '.join(EFFECTS)})")
        if not isinstance(table, dict):
            raise InputError(f"{kw}: expected a table of parameters")
        if table.get("enabled", True) is False:
            continue
        effects[ename] = _effect_params(EFFECTS[ename], table, kw)
    return effects


def _effect_params(eff, table: dict[str, Any], kw: str) -> dict[str, float]:
    vals = eff.defaults()
    names = [p.name for p in eff.params]
    for pk, pv in table.items():
        if pk in ("enabled", "source", "note"):
            continue
        if pk not in names:
            raise InputError(f"{kw}.{pk}: unknown parameter{did_you_mean(pk, names)} (expected {', '.join(names)})")
        spec = eff.param(pk)
        if isinstance(pv, dict):
            check_effect_entry(pv, f"{kw}.{pk}")
        v = parse_quantity(pv["value"] if isinstance(pv, dict) else pv, spec.unit, f"{kw}.{pk}")
        lo, hi = spec.bounds
        if v < lo or v > hi:
            raise InputError(f"{kw}.{pk}: {v:g} {spec.unit} is outside the admissible range [{lo:g}, {hi:g}]")
        vals[pk] = v
    return vals

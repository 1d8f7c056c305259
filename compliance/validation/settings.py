"""Validation settings: the TOML of docs/validation.md (replay modes, locate, limits, windows, overlays).

``load_settings`` reads a file, ``apply_overrides`` sets command-line ``KEY.PATH=VALUE`` items into
its table, ``settings_from_dict`` checks a table and freezes it as :class:`ValidationSettings`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from compliance.errors import InputError, did_you_mean
from compliance.model.toml_file import check_table, read_toml
from compliance.units import parse_quantity
from compliance.validation.fit_metrics import (
    DEFAULT_LIMITS,
    MEASURES,
    SIGNAL_UNITS,
    WINDOW_KINDS,
    ErrorLimits,
    ErrorWindow,
    MetricSettings,
)
from compliance.validation.locate import LocateSettings
from compliance.validation.replay import MODES, NOISE_CHOICES

MAX_OVERLAY_POINTS = 3000


@dataclass(frozen=True)
class ValidationSettings:
    """Everything a validation run can be told.

    Attributes
    ----------
    modes : tuple of str
        Replay modes to run (``closed_loop``, ``plant_only``).
    noise : str
        Closed-loop noise replay (``auto``, ``recorded``, ``none``; see ``compliance.validation.replay``).
    locate : LocateSettings
    metrics : MetricSettings
    overlay_points : int
        Largest number of points per overlay / residual trace in the results (<= 3000).
    """

    modes: tuple[str, ...] = MODES
    noise: str = "auto"
    locate: LocateSettings = field(default_factory=LocateSettings)
    metrics: MetricSettings = field(default_factory=MetricSettings)
    overlay_points: int = MAX_OVERLAY_POINTS

    def __post_init__(self):
        if not self.modes or any(m not in MODES for m in self.modes):
            raise InputError(f"replay.modes = {list(self.modes)!r}; expected a non-empty list of {', '.join(MODES)}")
        if self.noise not in NOISE_CHOICES:
            raise InputError(f"replay.noise = {self.noise!r}; expected one of {', '.join(NOISE_CHOICES)}")
        if not (isinstance(self.overlay_points, int) and 10 <= self.overlay_points <= MAX_OVERLAY_POINTS):
            raise InputError(f"overlays.points = {self.overlay_points!r}; expected an integer 10..{MAX_OVERLAY_POINTS}")


# ----------------------------------------------------------------------------------- settings
_SECTIONS = {
    "replay": ("modes", "noise"),
    "locate": ("k_on", "k_off", "smoothing", "min_duration", "merge_gap", "min_floor_pu"),
    "metrics": ("error_filter_cutoff", "transient_duration"),
    "overlays": ("points",),
    "limits": (),
    "windows": (),
}
_LOCATE_UNITS = {"smoothing": "s", "min_duration": "s", "merge_gap": "s"}


def _number(value, unit: str, where: str) -> float:
    if isinstance(value, bool):
        raise InputError(f"{where}: expected a number{' or a quantity in ' + unit if unit else ''}, got {value!r}")
    if isinstance(value, (int, float)):
        return float(value)
    if isinstance(value, str) and unit:
        return parse_quantity(value, unit, where)
    try:
        return float(value)
    except (TypeError, ValueError):
        raise InputError(f"{where}: expected a number, got {value!r}") from None


def settings_from_dict(data: dict, where: str = "<settings>") -> ValidationSettings:
    """Validate a settings mapping (the TOML layout of docs/validation.md).

    Raises
    ------
    InputError
        Unknown section or key (with the closest match), a value of the wrong kind.
    """
    if not isinstance(data, dict):
        raise InputError(f"{where}: expected a table")
    for sec in data:
        if sec not in _SECTIONS:
            raise InputError(f"{where}: unknown section [{sec}]{did_you_mean(sec, _SECTIONS)} (expected {', '.join(_SECTIONS)})")
    for sec, keys in _SECTIONS.items():
        if keys and sec in data:
            if not isinstance(data[sec], dict):
                raise InputError(f"{where}: [{sec}] must be a table")
            for k in data[sec]:
                if k not in keys:
                    raise InputError(f"{where}: {sec}.{k}: unknown key{did_you_mean(k, keys)} (expected {', '.join(keys)})")
    rep = data.get("replay", {})
    modes = rep.get("modes", list(MODES))
    if isinstance(modes, str):
        modes = list(MODES) if modes == "both" else [modes]
    if not isinstance(modes, list) or not all(isinstance(m, str) for m in modes):
        raise InputError(f"{where}: replay.modes: expected a list of {', '.join(MODES)} (or \"both\")")
    for m in modes:
        if m not in MODES:
            raise InputError(f"{where}: replay.modes: '{m}' is not one of {', '.join(MODES)}{did_you_mean(m, MODES)}")
    noise = rep.get("noise", "auto")
    loc = {k: _number(v, _LOCATE_UNITS.get(k, ""), f"{where}: locate.{k}") for k, v in data.get("locate", {}).items()}
    try:
        locate_settings = LocateSettings(**loc)
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None
    met = data.get("metrics", {})
    cutoff = _number(met.get("error_filter_cutoff", 20.0), "Hz", f"{where}: metrics.error_filter_cutoff")
    tdur = _number(met.get("transient_duration", 1.0), "s", f"{where}: metrics.transient_duration")
    limits = dict(_limits_from_dict(data.get("limits", {}), where))
    windows = tuple(_windows_from_list(data.get("windows", []), where))
    points = data.get("overlays", {}).get("points", MAX_OVERLAY_POINTS)
    try:
        metrics = MetricSettings(limits=limits, error_filter_cutoff=cutoff, transient_duration=tdur, windows=windows)
        return ValidationSettings(modes=tuple(modes), noise=noise, locate=locate_settings, metrics=metrics, overlay_points=points)
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None


def _limits_from_dict(table, where: str):
    limits = dict(DEFAULT_LIMITS)
    if not isinstance(table, dict):
        raise InputError(f"{where}: [limits] must be a table of [limits.SIGNAL.KIND] tables")
    for sig, kinds in table.items():
        if sig not in SIGNAL_UNITS:
            raise InputError(f"{where}: limits.{sig}: unknown signal{did_you_mean(sig, SIGNAL_UNITS)} (expected {', '.join(SIGNAL_UNITS)})")
        if not isinstance(kinds, dict):
            raise InputError(f"{where}: limits.{sig} must be a table of steady / transient tables")
        for kind, vals in kinds.items():
            if kind not in WINDOW_KINDS:
                raise InputError(f"{where}: limits.{sig}.{kind}: unknown window kind{did_you_mean(kind, WINDOW_KINDS)} (expected {', '.join(WINDOW_KINDS)})")
            if not isinstance(vals, dict):
                raise InputError(f"{where}: limits.{sig}.{kind} must be a table of {', '.join(MEASURES)}")
            cur = limits.get((sig, kind), ErrorLimits()).as_dict()
            for m, v in vals.items():
                kw = f"{where}: limits.{sig}.{kind}.{m}"
                if m not in MEASURES:
                    raise InputError(f"{kw}: unknown measure{did_you_mean(m, MEASURES)} (expected {', '.join(MEASURES)})")
                if isinstance(v, str) and v.strip().lower() in ("none", "off"):
                    cur[m] = None
                    continue
                x = _number(v, "", kw)
                if not (math.isfinite(x) and x >= 0):
                    raise InputError(f"{kw}: {v!r}; expected a limit >= 0 in per unit (or \"none\")")
                cur[m] = x
            limits[(sig, kind)] = ErrorLimits(**cur)
    return limits


def _windows_from_list(items, where: str):
    if not isinstance(items, list):
        raise InputError(f"{where}: windows must be an array of tables ([[windows]])")
    for i, w in enumerate(items):
        kw = f"{where}: windows[{i}]"
        check_table(w, kw, ("name", "start", "end", "kind"), expected="a table with name, start, end, kind")
        for k in ("start", "end"):
            if k not in w:
                raise InputError(f"{kw}: missing '{k}' (a time such as \"8 s\")")
        start = _number(w["start"], "s", f"{kw}.start")
        end = _number(w["end"], "s", f"{kw}.end")
        kind = w.get("kind", "transient")
        try:
            yield ErrorWindow(str(w.get("name", f"window {i + 1}")), start, end, str(kind))
        except InputError as exc:
            raise InputError(f"{kw}: {exc}") from None


def load_settings(path) -> ValidationSettings:
    """Read a validation settings TOML file (docs/validation.md)."""
    return settings_from_dict(read_settings_table(path), str(path))


def read_settings_table(path) -> dict:
    """The raw table of a settings TOML file (to apply command-line overrides before validating)."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: settings file not found")
    return read_toml(p, "validation settings file")[0]


def apply_overrides(table: dict, items, where: str = "--setting") -> dict:
    """Set ``KEY.PATH=VALUE`` items into a settings table (numbers parsed, other text kept)."""
    out = {k: (dict(v) if isinstance(v, dict) else v) for k, v in table.items()}
    for item in items or ():
        if "=" not in item:
            raise InputError(f"{where}: '{item}' must look like KEY.PATH=VALUE, e.g. limits.position.steady.max_error=0.02")
        key, value = (s.strip() for s in item.split("=", 1))
        parts = key.split(".")
        if len(parts) < 2 or not all(parts):
            raise InputError(f"{where}: '{key}' must be a dotted path such as locate.k_on or limits.position.steady.max_error")
        try:
            val: object = float(value)
        except ValueError:
            val = [s.strip() for s in value.split(",")] if key == "replay.modes" and "," in value else value
        node = out
        for p in parts[:-1]:
            nxt = node.get(p)
            if not isinstance(nxt, dict):
                nxt = {} if nxt is None else nxt
                if not isinstance(nxt, dict):
                    raise InputError(f"{where}: '{key}': '{p}' is not a table")
            nxt = dict(nxt)
            node[p] = nxt
            node = nxt
        node[parts[-1]] = val
    return out

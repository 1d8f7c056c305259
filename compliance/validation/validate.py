"""Validate a plant model against a recording: replay, locate, measure (sequencing only, no physics).

``validate(cfg, recording, metadata, settings) -> dict`` returns the versioned, JSON-ready
results described in ``docs/validation-schema.md``; ``load_settings`` reads the settings
TOML (limits, locate parameters, windows) of ``docs/validation.md``.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from compliance.errors import did_you_mean
from compliance import __version__
from compliance.model.config import PlantConfig
from compliance.errors import InputError
from compliance.validation.locate import LocateSettings, locate, merge_across_signals
from compliance.validation.regimes import REGIME_NAMES, compute_regimes
from compliance.validation.replay import MODES, NOISE_CHOICES, is_uniform, load_from_metadata, replay, replay_config
from compliance.units import parse_quantity
from compliance.validation.fit_metrics import (
    MEASURES,
    SIGNAL_UNITS,
    WINDOW_KINDS,
    ErrorLimits,
    ErrorWindow,
    MetricSettings,
    derive_windows,
    per_unit_bases,
    signal_fit,
    window_metrics,
)

SCHEMA = "govcheck.validation/1"
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
    from compliance.validation.fit_metrics import DEFAULT_LIMITS

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
        if not isinstance(w, dict):
            raise InputError(f"{kw}: expected a table with name, start, end, kind")
        unknown = set(w) - {"name", "start", "end", "kind"}
        if unknown:
            raise InputError(f"{kw}: unknown key '{sorted(unknown)[0]}' (expected name, start, end, kind)")
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
    try:
        return tomllib.loads(p.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{p}: not valid TOML ({exc})") from None


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


# ----------------------------------------------------------------------------------- helpers
def decimation_indices(values: np.ndarray, max_points: int) -> np.ndarray:
    """Indexes keeping each bucket's minimum and maximum (at most ``max_points``, in order)."""
    y = np.asarray(values, dtype=float)
    n = y.size
    if n <= max_points:
        return np.arange(n)
    buckets = max(1, (max_points - 2) // 2)
    size = int(math.ceil(n / buckets))
    full = (n // size) * size
    blocks = y[:full].reshape(-1, size)
    base = np.arange(blocks.shape[0]) * size
    idx = [base + np.argmin(blocks, axis=1), base + np.argmax(blocks, axis=1)]
    if full < n:
        tail = y[full:]
        idx.append(np.array([full + int(np.argmin(tail)), full + int(np.argmax(tail))]))
    out = np.unique(np.concatenate(idx + [np.array([0, n - 1])]))
    return out[:max_points] if out.size > max_points else out


def _clean(obj):
    """Make a results tree JSON-ready: numpy scalars to Python, non-finite floats to None."""
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return [_clean(v) for v in obj.tolist()]
    if isinstance(obj, (np.bool_, bool)):
        return bool(obj)
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        f = float(obj)
        return f if math.isfinite(f) else None
    return obj


def _round_list(a: np.ndarray, digits: int = 9) -> list:
    """JSON-ready list with ``digits`` significant digits relative to the largest |value| (non-finite -> None)."""
    v = np.asarray(a, dtype=float)
    finite = np.isfinite(v)
    big = float(np.max(np.abs(v[finite]))) if finite.any() else 0.0
    if big > 0:
        d = int(digits - 1 - math.floor(math.log10(big)))
        v = np.round(v * 10.0**d) / 10.0**d if d >= 0 else np.round(v / 10.0**-d) * 10.0**-d
    out = v.tolist()
    if not finite.all():
        out = [x if f else None for x, f in zip(out, finite.tolist())]
    return out


# ----------------------------------------------------------------------------------- orchestration
def validate(cfg: PlantConfig, recording: pd.DataFrame, metadata: dict | None = None, settings: ValidationSettings | None = None) -> dict:
    """Replay a recording with a model in each mode, locate the misfit and measure it.

    Parameters
    ----------
    cfg : PlantConfig
    recording : pandas.DataFrame
        Canonical columns (``read_recording``).
    metadata : dict, optional
        Sidecar metadata (``read_recording``).
    settings : ValidationSettings, optional

    Returns
    -------
    dict
        Results (``docs/validation-schema.md``), JSON-ready.
    """
    settings = settings or ValidationSettings()
    metadata = dict(metadata or {})
    where = str(metadata.get("source_path") or "recording")
    warnings: list[str] = []
    t = recording["time"].to_numpy(dtype=float)
    if t.size < 10:
        raise InputError(f"{where}: {t.size} samples; validation needs at least 10")
    # supply pressure: sidecar, else the recorded one, else the configuration's
    cond = dict(metadata.get("conditions") or {}) if isinstance(metadata.get("conditions"), dict) else {}
    if "supply_pressure" not in cond and "supply_pressure" in recording:
        cond["supply_pressure"] = float(np.median(recording["supply_pressure"].to_numpy(dtype=float)))
        warnings.append(f"no conditions.supply_pressure in the sidecar: using the recorded median {cond['supply_pressure']/1e5:.3f} bar abs")
        metadata["conditions"] = cond
    if metadata.get("plant") and metadata["plant"] != cfg.name:
        warnings.append(f"the sidecar says the recording was taken on '{metadata['plant']}', the model is '{cfg.name}'")
    if "load_force" not in cond:
        warnings.append("no conditions.load_force in the sidecar: the replay assumes no load")
    run_cfg, overrides = replay_config(cfg, metadata)
    load = load_from_metadata(metadata)
    supply = run_cfg.p("air.supply_pressure")
    regimes = compute_regimes(recording, run_cfg, load, supply)
    bases_info = per_unit_bases(run_cfg, supply)
    bases = {k: v["value"] for k, v in bases_info.items()}
    stroke = run_cfg.p("cylinder.stroke")
    ref = recording["reference"].to_numpy(dtype=float) if "reference" in recording else None
    windows = list(settings.metrics.windows) or derive_windows(t, ref, settings.metrics.transient_duration, stroke)
    modes_out: dict[str, dict] = {}
    traces: dict[str, tuple[dict, dict]] = {}
    floors_out: dict[str, float] = {}
    conditions = None
    for mode in settings.modes:
        need = "reference" if mode == "closed_loop" else "valve_command"
        if need not in recording and len(settings.modes) > 1:
            warnings.append(f"{mode} replay skipped: the recording has no '{need}' column")
            continue
        sim = replay(cfg, recording, metadata, mode, noise=settings.noise)
        conditions = sim.attrs["conditions"]
        exclude = ("valve_command",) if mode == "plant_only" else ()
        located, floors, levels = locate(recording, sim, regimes, bases, settings.locate, exclude=exclude)
        floors_out.update(floors)
        events = merge_across_signals(located, regimes, settings.locate.merge_gap)
        signals = [s for s in floors]  # compared signals, in SIGNALS order
        fits = {s: {**signal_fit(recording[s].to_numpy(dtype=float), sim[s].to_numpy(dtype=float)), "unit": SIGNAL_UNITS[s]} for s in signals}
        rows = window_metrics(t, {s: recording[s].to_numpy(dtype=float) for s in signals}, {s: sim[s].to_numpy(dtype=float) for s in signals},
                              bases, windows, settings.metrics)
        overlays, resid = {}, {}
        for s in signals + (["valve_command"] if mode == "plant_only" and "valve_command" in recording else []):
            y = recording[s].to_numpy(dtype=float)
            yh = sim[s].to_numpy(dtype=float)
            idx = decimation_indices(y, settings.overlay_points)
            overlays[s] = {"time": _round_list(t[idx], 12), "recorded": _round_list(y[idx]), "simulated": _round_list(yh[idx]),
                           "unit": SIGNAL_UNITS[s], "role": "input" if s in exclude else "output"}
        for s in signals:
            r = recording[s].to_numpy(dtype=float) - sim[s].to_numpy(dtype=float)
            idx = decimation_indices(r, settings.overlay_points)
            resid[s] = {"time": _round_list(t[idx], 12), "residual": _round_list(r[idx]), "smoothed_abs": _round_list(levels[s][idx]),
                        "threshold_on": settings.locate.k_on * floors[s], "threshold_off": settings.locate.k_off * floors[s],
                        "noise_floor": floors[s], "unit": SIGNAL_UNITS[s]}
        modes_out[mode] = {
            "noise_replay": bool(sim.attrs["noise_replay"]),
            "compared_signals": signals,
            "fits": fits,
            "window_metrics": rows,
            "pass": all(r["pass"] for r in rows),
            "located_windows": [w.to_dict() for w in located],
            "events": events,
        }
        traces[mode] = (overlays, resid)
    if not modes_out:
        raise InputError(f"{where}: no replay mode could run (needs 'reference' for closed_loop or 'valve_command' for plant_only)")
    dt = np.diff(t)
    result = {
        "schema": SCHEMA,
        "tool": {"name": "govcheck", "version": __version__},
        "recording": {
            "path": metadata.get("source_path"),
            "format": metadata.get("format"),
            "description": metadata.get("description"),
            "plant": metadata.get("plant"),
            "samples": int(t.size),
            "start": float(t[0]),
            "end": float(t[-1]),
            "duration": float(t[-1] - t[0]),
            "sample_time_median": float(np.median(dt)),
            "uniform": bool(is_uniform(t)),
            "columns": [str(c) for c in recording.columns],
        },
        "plant": {"name": cfg.name, "path": cfg.path, "digest": cfg.digest, "effects": sorted(cfg.effects), "overrides": overrides},
        "conditions": conditions,
        "settings": {
            "modes": list(settings.modes),
            "noise": settings.noise,
            "locate": {k: getattr(settings.locate, k) for k in ("k_on", "k_off", "smoothing", "min_duration", "merge_gap", "min_floor_pu")},
            "metrics": {"error_filter_cutoff": settings.metrics.error_filter_cutoff, "transient_duration": settings.metrics.transient_duration},
            "limits": [{"signal": s, "kind": k, **lim.as_dict()} for (s, k), lim in sorted(settings.metrics.limits.items())],
            "overlay_points": settings.overlay_points,
        },
        "per_unit_bases": bases_info,
        "noise_floors": {s: {"value": v, "unit": SIGNAL_UNITS[s]} for s, v in floors_out.items()},
        "windows": [{"name": w.name, "start": w.start, "end": w.end, "kind": w.kind} for w in windows],
        "regimes": {
            "names": [n for n in REGIME_NAMES if n in regimes.masks],
            "fractions": regimes.fractions(),
            "thresholds": regimes.thresholds,
        },
        "modes": modes_out,
        "summary": {
            "pass": all(m["pass"] for m in modes_out.values()),
            "failed_rows": {m: sum(not r["pass"] for r in v["window_metrics"]) for m, v in modes_out.items()},
            "located_windows": {m: len(v["located_windows"]) for m, v in modes_out.items()},
        },
        "warnings": warnings,
    }
    result = _clean(result)
    for mode, (overlays, resid) in traces.items():  # already JSON-ready (rounded lists)
        result["modes"][mode]["overlays"] = overlays
        result["modes"][mode]["residuals"] = {s: {k: (_clean(v) if not isinstance(v, list) else v) for k, v in d.items()} for s, d in resid.items()}
    return result

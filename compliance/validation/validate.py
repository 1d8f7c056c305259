"""Validate a plant model against a recording: replay, locate, measure (sequencing only, no physics).

``validate(cfg, recording, metadata, settings) -> dict`` returns the versioned, JSON-ready
results described in ``docs/validation-schema.md``; the settings TOML (limits, locate
parameters, windows) of ``docs/validation.md`` is read in :mod:`compliance.validation.settings`.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from compliance.version import __version__
from compliance.errors import InputError
from compliance.files.jsonable import jsonable
from compliance.model.config import PlantConfig
from compliance.validation.fit_metrics import SIGNAL_UNITS, derive_windows, per_unit_bases, signal_fit, window_metrics
from compliance.validation.locate import locate, merge_across_signals
from compliance.validation.regimes import REGIME_NAMES, compute_regimes
from compliance.validation.replay import replay
from compliance.validation.replay_conditions import replay_config
from compliance.validation.resampling import is_uniform
from compliance.validation.settings import MAX_OVERLAY_POINTS, ValidationSettings, apply_overrides, load_settings
from compliance.validation.settings import read_settings_table, settings_from_dict

__all__ = [  # the settings are read beside this module and stay importable from it
    "MAX_OVERLAY_POINTS", "SCHEMA", "ValidationSettings", "apply_overrides", "decimation_indices", "load_settings",
    "read_settings_table", "settings_from_dict", "validate",
]

SCHEMA = "govcheck.validation/1"


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
    t = recording["time"].to_numpy(dtype=float)
    if t.size < 10:
        raise InputError(f"{where}: {t.size} samples; validation needs at least 10")
    warnings = _sidecar_warnings(cfg, metadata)
    run_cfg, overrides = replay_config(cfg, metadata, recording)
    sims: dict[str, pd.DataFrame] = {}
    for mode in settings.modes:
        need = "reference" if mode == "closed_loop" else "valve_command"
        if need not in recording and len(settings.modes) > 1:
            warnings.append(f"{mode} replay skipped: the recording has no '{need}' column")
            continue
        sims[mode] = replay(cfg, recording, metadata, mode, noise=settings.noise)
    conditions = next(iter(sims.values())).attrs["conditions"] if sims else None
    if conditions is not None:
        warnings += _assumed(conditions, next(iter(sims.values())).attrs["notes"])
    load = conditions["load_force"] if conditions else None
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
    for mode, sim in sims.items():
        modes_out[mode], traces[mode], floors = _compare_mode(recording, sim, mode, regimes, bases, windows, settings)
        floors_out.update(floors)
    if not modes_out:
        raise InputError(f"{where}: no replay mode could run (needs 'reference' for closed_loop or 'valve_command' for plant_only)")
    result = {
        "schema": SCHEMA,
        "tool": {"name": "govcheck", "version": __version__},
        "recording": _recording_summary(recording, metadata),
        "plant": {"name": cfg.name, "path": cfg.path, "digest": cfg.digest, "effects": sorted(cfg.effects), "overrides": overrides},
        "conditions": conditions,
        "settings": _settings_summary(settings),
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
    result = jsonable(result)
    for mode, (overlays, resid) in traces.items():  # already JSON-ready (rounded lists)
        result["modes"][mode]["overlays"] = overlays
        result["modes"][mode]["residuals"] = {s: {k: (jsonable(v) if not isinstance(v, list) else v) for k, v in d.items()} for s, d in resid.items()}
    return result


def _sidecar_warnings(cfg: PlantConfig, metadata: dict) -> list[str]:
    """What the sidecar leaves to assumption (the replay's own fallbacks are in its conditions)."""
    warnings: list[str] = []
    if metadata.get("plant") and metadata["plant"] != cfg.name:
        warnings.append(f"the sidecar says the recording was taken on '{metadata['plant']}', the model is '{cfg.name}'")
    return warnings


def _assumed(conditions: dict, notes: list) -> list[str]:
    """Warnings for the conditions the replay took from elsewhere than the sidecar."""
    out = []
    if not conditions["supply_pressure_source"].startswith("sidecar"):
        source = conditions["supply_pressure_source"].split(" (")[0]
        out.append(f"no conditions.supply_pressure in the sidecar: {conditions['supply_pressure']/1e5:.3f} bar abs, the {source}")
    if not conditions["load_source"].startswith("sidecar"):
        out.append(conditions["load_source"])
    out += [n for n in notes if "drives the plant" in n]
    return out


def _compare_mode(recording: pd.DataFrame, sim: pd.DataFrame, mode: str, regimes, bases: dict, windows, settings):
    """Locate and measure one replay mode's misfit.

    Returns
    -------
    tuple
        (the mode's results, its (overlays, residuals) traces, noise floors by signal).
    """
    t = recording["time"].to_numpy(dtype=float)
    exclude = ("valve_command",) if mode == "plant_only" else ()
    switch = sim.attrs["conditions"].get("command_from")
    located, floors, levels = locate(recording, sim, regimes, bases, settings.locate, exclude=exclude,
                                     command_input_from=None if switch is None or mode != "closed_loop" else t[0] + switch)
    events = merge_across_signals(located, regimes, settings.locate.merge_gap)
    signals = [s for s in floors]  # compared signals, in SIGNALS order
    fits = {s: {**signal_fit(recording[s].to_numpy(dtype=float), sim[s].to_numpy(dtype=float)), "unit": SIGNAL_UNITS[s]} for s in signals}
    rows = window_metrics(t, {s: recording[s].to_numpy(dtype=float) for s in signals}, {s: sim[s].to_numpy(dtype=float) for s in signals},
                          bases, windows, settings.metrics)
    shown = signals + (["valve_command"] if mode == "plant_only" and "valve_command" in recording else [])
    overlays = {s: _overlay(t, recording[s].to_numpy(dtype=float), sim[s].to_numpy(dtype=float), settings.overlay_points,
                            "input" if s in exclude else "output", SIGNAL_UNITS[s]) for s in shown}
    resid = {s: _residual(t, recording[s].to_numpy(dtype=float) - sim[s].to_numpy(dtype=float), levels[s], floors[s], settings,
                          SIGNAL_UNITS[s]) for s in signals}
    out = {
        "noise_replay": bool(sim.attrs["noise_replay"]),
        "compared_signals": signals,
        "fits": fits,
        "window_metrics": rows,
        "pass": all(r["pass"] for r in rows),
        "located_windows": [w.to_dict() for w in located],
        "events": events,
    }
    return out, (overlays, resid), floors


def _overlay(t, y, yh, max_points: int, role: str, unit: str) -> dict:
    """Recorded and simulated trace of one signal, decimated (min/max per bucket) and rounded."""
    idx = decimation_indices(y, max_points)
    return {"time": _round_list(t[idx], 12), "recorded": _round_list(y[idx]), "simulated": _round_list(yh[idx]),
            "unit": unit, "role": role}


def _residual(t, r, level, floor: float, settings, unit: str) -> dict:
    """Residual of one signal, its smoothed magnitude and the locate thresholds, decimated and rounded."""
    idx = decimation_indices(r, settings.overlay_points)
    return {"time": _round_list(t[idx], 12), "residual": _round_list(r[idx]), "smoothed_abs": _round_list(level[idx]),
            "threshold_on": settings.locate.k_on * floor, "threshold_off": settings.locate.k_off * floor,
            "noise_floor": floor, "unit": unit}


def _recording_summary(recording: pd.DataFrame, metadata: dict) -> dict:
    """What was replayed: source, sample count, time span and grid."""
    t = recording["time"].to_numpy(dtype=float)
    return {
        "path": metadata.get("source_path"),
        "format": metadata.get("format"),
        "description": metadata.get("description"),
        "plant": metadata.get("plant"),
        "samples": int(t.size),
        "start": float(t[0]),
        "end": float(t[-1]),
        "duration": float(t[-1] - t[0]),
        "sample_time_median": float(np.median(np.diff(t))),
        "uniform": bool(is_uniform(t)),
        "columns": [str(c) for c in recording.columns],
    }


def _settings_summary(settings: ValidationSettings) -> dict:
    """The settings the run used, as plain data."""
    return {
        "modes": list(settings.modes),
        "noise": settings.noise,
        "locate": {k: getattr(settings.locate, k) for k in ("k_on", "k_off", "smoothing", "min_duration", "merge_gap", "min_floor_pu")},
        "metrics": {"error_filter_cutoff": settings.metrics.error_filter_cutoff, "transient_duration": settings.metrics.transient_duration},
        "limits": [{"signal": s, "kind": k, **lim.as_dict()} for (s, k), lim in sorted(settings.metrics.limits.items())],
        "overlay_points": settings.overlay_points,
    }

"""Synthetic test recordings from the model, shaped like the practice recordings.

``synthesise`` runs the closed-loop practice test (ANSWERS.md of the practice recordings)
on any configuration, with the practice sensors, and returns a canonical recording with its
sidecar metadata; ``write_recording`` stores it as the canonical CSV (optionally gzip) plus
the ``NAME.toml`` sidecar of docs/recording-format.md. The validation tests and
the diagnosis benchmarks use both.
"""

from __future__ import annotations

import gzip
import math
import os
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

from compliance.model.config import PlantConfig
from compliance.errors import InputError
from compliance.simulation.profiles import Profile
from compliance.recordings.reader import sidecar_path
from compliance.simulation import Scenario, SensorNoise
from compliance.plants import simulate

CANONICAL_COLUMNS = ("time", "position", "reference", "valve_command", "pressure_a", "pressure_b", "supply_pressure")

# practice test (ANSWERS.md): steps of +2/+5/+10 % of stroke and back, then an 8 mm sinusoid
PRACTICE_STEPS = ((2.0, 0.02), (5.0, 0.0), (8.0, 0.05), (11.0, 0.0), (14.0, 0.10), (17.0, 0.0))
PRACTICE_SINE_START = 20.0  # s
PRACTICE_SINE_AMPLITUDE = 8e-3  # m
PRACTICE_SINE_OMEGA = math.pi / 10.0  # rad/s
PRACTICE_DURATION = 30.0  # s
# practice sensors: position N(0, 20 um) + 10 um steps; pressures N(0, 300 Pa) + 16 bits over 0-10 bar
PRACTICE_NOISE = SensorNoise(position_std=20e-6, position_quantum=10e-6, pressure_std=300.0, pressure_quantum=1.0e6 / 65535.0)
PROFILE_KINDS = ("practice", "steps")


def practice_profile(x0: float, stroke: float, duration: float = PRACTICE_DURATION, sine: bool = True) -> Profile:
    """Set-point of the practice test [m].

    2 s hold at ``x0``; +2 % of stroke at 2 s, back at 5 s; +5 % at 8 s, back at 11 s; +10 % at
    14 s, back at 17 s; then ``x0 + 8 mm * sin(pi/10 * (t - 20))`` from 20 s to 30 s (one
    half-period, ending at ``x0``).

    Parameters
    ----------
    x0 : float
        Initial position [m].
    stroke : float
        Cylinder stroke [m] (the step sizes are percentages of it).
    duration : float
        End of the profile [s] (held after it).
    sine : bool
        Include the sinusoid (False: steps only).
    """
    times = [0.0]
    values = [x0]
    for t, frac in PRACTICE_STEPS:
        times += [t, t]
        values += [values[-1], x0 + frac * stroke]
    if sine and duration > PRACTICE_SINE_START:
        t_end = min(duration, PRACTICE_SINE_START + math.pi / PRACTICE_SINE_OMEGA)
        ts = np.linspace(PRACTICE_SINE_START, t_end, int(round((t_end - PRACTICE_SINE_START) / 0.005)) + 1)
        times += list(ts)
        values += list(x0 + PRACTICE_SINE_AMPLITUDE * np.sin(PRACTICE_SINE_OMEGA * (ts - PRACTICE_SINE_START)))
    lo, hi = min(values), max(values)
    if lo < 0.0 or hi > stroke:
        raise InputError(f"practice profile from x0 = {x0*1e3:.1f} mm leaves the stroke 0..{stroke*1e3:.0f} mm "
                         f"(reaches {lo*1e3:.1f}..{hi*1e3:.1f} mm)")
    return Profile(np.array(times), np.array(values))


def synthesise(
    cfg: PlantConfig,
    profile_kind: str = "practice",
    x0: float = 0.06,
    load: float | str | None = 7000.0,
    kd: float | None = None,
    noise: SensorNoise | None = PRACTICE_NOISE,
    seed: int = 0,
    *,
    duration: float = PRACTICE_DURATION,
    reference: Profile | None = None,
    description: str | None = None,
) -> tuple[pd.DataFrame, dict]:
    """A recording of the practice test simulated with ``cfg`` (closed loop, practice sensors).

    Parameters
    ----------
    cfg : PlantConfig
        Plant (with any effects switched on) the "bench" is.
    profile_kind : {"practice", "steps"}
        The practice set-point, or its steps only (no sinusoid). Ignored when ``reference`` is given.
    x0 : float
        Initial position [m].
    load : float, "curve" or None
        Closing load [N] (> 0 closes).
    kd : float, optional
        Derivative gain [V*s/m] (default: the configuration's).
    noise : SensorNoise or None
        Sensor noise (default the practice sensors; None: exact signals).
    seed : int
        Noise seed (deterministic).
    duration : float
        [s].
    reference : Profile, optional
        Any other set-point [m].
    description : str, optional
        Sidecar description.

    Returns
    -------
    (pandas.DataFrame, dict)
        Canonical columns only (time, position, reference, valve_command, pressure_a,
        pressure_b, supply_pressure; SI, absolute pressures) and the sidecar metadata.
    """
    if profile_kind not in PROFILE_KINDS and reference is None:
        raise InputError(f"profile_kind '{profile_kind}' is not one of {', '.join(PROFILE_KINDS)} (or pass reference=Profile)")
    if kd is not None:
        cfg = cfg.replace(params={"controller.kd": float(kd)})
    stroke = cfg.p("cylinder.stroke")
    if reference is None:
        reference = practice_profile(x0, stroke, duration, sine=(profile_kind == "practice"))
        kind = profile_kind
    else:
        kind = "custom"
    df = simulate(cfg, Scenario(duration=duration, initial_position=x0, reference=reference, load=load, noise=noise, seed=seed))
    rec = df[list(CANONICAL_COLUMNS)].copy()
    rec.attrs = {}
    return rec, synthesis_metadata(cfg, kind, x0, load, noise, seed, description)


def synthesis_metadata(cfg: PlantConfig, kind: str, x0: float, load, noise: SensorNoise | None, seed: int,
                       description: str | None = None) -> dict:
    """Sidecar metadata of a synthetic recording: plant, test conditions, controller, how it was made.

    Parameters
    ----------
    cfg : PlantConfig
        The plant simulated (gains already replaced).
    kind : str
        ``practice``, ``steps`` or ``custom`` (the set-point).
    x0 : float
        Initial position [m].
    load : float, "curve" or None
        Closing load [N].
    noise : SensorNoise or None
        Sensor noise applied.
    seed : int
        Noise seed.
    description : str, optional
        Default: the practice test written out.
    """
    if description is None:
        description = (
            "Synthetic closed-loop test (govcheck recording_synth): 2 s hold, 2/5/10 % steps (3 s each, back to "
            "the start position)" + (", then an 8 mm sinusoid at pi/10 rad/s" if kind == "practice" else "")
        )
    return {
        "plant": cfg.name,
        "description": description,
        "conditions": {
            "load_force": load if isinstance(load, str) else float(load or 0.0),
            "initial_position": float(x0),
            "supply_pressure": cfg.p("air.supply_pressure"),
        },
        "controller": {
            "kp": cfg.p("controller.kp"),
            "ki": cfg.p("controller.ki"),
            "kd": cfg.p("controller.kd"),
            "sample_time": cfg.p("controller.sample_time"),
        },
        "synthesis": {
            "generator": "compliance.recordings.synth",
            "profile": kind,
            "seed": int(seed),
            "position_noise_std": noise.position_std if noise else 0.0,
            "position_quantum": noise.position_quantum if noise else 0.0,
            "pressure_noise_std": noise.pressure_std if noise else 0.0,
            "pressure_quantum": noise.pressure_quantum if noise else 0.0,
        },
    }


# ----------------------------------------------------------------------------------- writing
def _toml_value(v, where: str) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        f = float(v)
        if math.isnan(f):
            return "nan"
        if math.isinf(f):
            return "inf" if f > 0 else "-inf"
        return repr(f)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(e, where) for e in v) + "]"
    raise InputError(f"{where}: cannot write {type(v).__name__} to the sidecar TOML")


def sidecar_text(metadata: dict) -> str:
    """TOML text of a sidecar mapping (scalars, lists, nested tables)."""
    lines: list[str] = []

    def table(d: dict, prefix: str):
        scalars = [(k, v) for k, v in d.items() if not isinstance(v, dict) and v is not None]
        tables = [(k, v) for k, v in d.items() if isinstance(v, dict)]
        if prefix and scalars:
            lines.append(f"[{prefix}]")
        for k, v in scalars:
            lines.append(f"{k} = {_toml_value(v, prefix + '.' + k if prefix else k)}")
        if scalars:
            lines.append("")
        for k, v in tables:
            table(v, f"{prefix}.{k}" if prefix else k)

    table(metadata, "")
    return "\n".join(lines).rstrip() + "\n"


def _atomic_write(path: Path, data: bytes) -> None:
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def write_recording(df: pd.DataFrame, metadata: dict | None, path, *, overwrite: bool = False) -> tuple[Path, Path | None]:
    """Write a canonical recording (``.csv`` or ``.csv.gz``) and its ``NAME.toml`` sidecar, atomically.

    Parameters
    ----------
    df : pandas.DataFrame
        Canonical columns (others are dropped); ``time``, ``position`` and ``valve_command`` required.
    metadata : dict or None
        Sidecar content (None: no sidecar). Keys added by ``read_recording`` (``source_path``,
        ``format``, ``columns``...) are not written.
    path : str or pathlib.Path
        Output ``NAME.csv`` or ``NAME.csv.gz``.
    overwrite : bool
        Replace existing files (default: refuse).

    Returns
    -------
    (pathlib.Path, pathlib.Path or None)
        The CSV and sidecar paths.
    """
    path = Path(path)
    name = path.name.lower()
    if not (name.endswith(".csv") or name.endswith(".csv.gz")):
        raise InputError(f"{path}: a canonical recording is written as NAME.csv or NAME.csv.gz")
    missing = [c for c in ("time", "position", "valve_command") if c not in df.columns]
    if missing:
        raise InputError(f"{path}: cannot write a recording without column(s) {', '.join(missing)}")
    side = sidecar_path(path) if metadata is not None else None
    for p in (path, side):
        if p is not None and p.exists() and not overwrite:
            raise InputError(f"{p}: exists; pass overwrite=True to replace it")
    path.parent.mkdir(parents=True, exist_ok=True)
    cols = [c for c in CANONICAL_COLUMNS if c in df.columns]
    text = df[cols].to_csv(index=False, float_format="%.10g", lineterminator="\n").encode("utf-8")
    _atomic_write(path, gzip.compress(text, mtime=0) if name.endswith(".gz") else text)
    if side is not None:
        drop = {"source_path", "format", "column_map", "columns", "dropped_rows"}
        _atomic_write(side, sidecar_text({k: v for k, v in metadata.items() if k not in drop}).encode("utf-8"))
    return path, side

"""A prepared run of the seal-friction bench: signals in SI, velocity, reversal and sliding masks.

The bench's own physics is the characterisation's (``characterise.friction_runs``): the piston
area and the friction as the drive force less the pressure force (Zillen et al. eq. 3). The
diagnosis adds what judging a friction law needs: where the piston slides steadily, the travel
after each reversal, the samples whose velocity is smeared across a reversal and the force noise.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.signal import savgol_filter

from compliance.characterise.friction_runs import friction_from_force, piston_area
from compliance.errors import InputError
from compliance.units import ATMOSPHERE_PA
from compliance.validation.recorded_noise import sensor_noise_std

REVERSAL_TRAVEL = 2e-3  # m of travel after a change of direction counted as "after reversal"
VELOCITY_WINDOW = 0.05  # s; Savitzky-Golay (quadratic) derivative window of the position
MIN_SLIDING_SPEED = 1e-3  # m/s; slower samples are not "steady sliding"


@dataclass
class Run:
    """One prepared bench run."""

    name: str
    seal: str
    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    pressure_gauge: np.ndarray
    friction: np.ndarray  # measured F - p_g * A [N] (friction plus bench bias)
    after_reversal: np.ndarray
    sliding: np.ndarray
    floor: float  # force noise [N]
    valid: np.ndarray  # samples whose velocity estimate is not smeared across a reversal

    @property
    def pressure(self) -> float:
        """Mean gauge pressure [Pa]."""
        return float(np.mean(self.pressure_gauge))


def seal_name(path: str) -> str:
    """Seal label from a file name: ``O-ring257_3bar.csv`` -> ``O-ring257`` (text before the pressure)."""
    stem = Path(path).name
    for suf in (".gz", ".csv", ".txt", ".tsv", ".dat", ".parquet", ".mat"):
        if stem.lower().endswith(suf):
            stem = stem[: -len(suf)]
    m = re.match(r"(.*?)[_\- ]?\d+(\.\d+)?\s*bar.*$", stem, flags=re.IGNORECASE)
    return (m.group(1) if m and m.group(1) else stem) or stem


def _reversal_masks(position: np.ndarray, velocity: np.ndarray, travel: float) -> tuple[np.ndarray, np.ndarray]:
    n = velocity.size
    after = np.zeros(n, dtype=bool)
    moving = np.abs(velocity) > MIN_SLIDING_SPEED
    sign = np.sign(velocity)
    last_sign = 0.0
    start_x = None
    for k in range(n):
        if moving[k] and sign[k] != last_sign:
            if last_sign != 0.0:
                start_x = position[k]
            last_sign = sign[k]
        if start_x is not None:
            if abs(position[k] - start_x) <= travel:
                after[k] = True
            else:
                start_x = None
    # the slow approach to a reversal belongs to it too
    after |= ~moving
    return after, moving & ~after


def prepare_runs(runs, bore: float | None) -> list[Run]:
    """Friction samples of each run: velocity, gauge pressure, measured friction, reversal masks.

    Parameters
    ----------
    runs : sequence of (DataFrame, metadata)
        ``read_recording`` output with ``time``, ``position``, ``pressure_a``, ``force``.
    bore : float or None
        Piston bore [m] (else the metadata's ``bore``).
    """
    out = []
    for frame, meta in runs:
        src = str(meta.get("source_path", "<recording>"))
        for col in ("time", "position", "pressure_a", "force"):
            if col not in frame.columns:
                raise InputError(f"{src}: a friction-bench run needs column '{col}' (has {', '.join(frame.columns)})")
        d = bore if bore is not None else meta.get("bore")
        if not isinstance(d, (int, float)) or not d > 0:
            raise InputError(f"{src}: no piston bore: pass --friction-bore \"25.7 mm\" or give 'bore' in the column map's [metadata]")
        area = piston_area(float(d))
        t = frame["time"].to_numpy(dtype=float)
        x = frame["position"].to_numpy(dtype=float)
        dt = float(np.median(np.diff(t)))
        w = max(5, int(round(VELOCITY_WINDOW / dt)) | 1)
        if t.size < 4 * w:
            raise InputError(f"{src}: {t.size} samples are too few for a friction diagnosis (need >= {4 * w})")
        v = savgol_filter(x, w, 2, deriv=1, delta=dt)
        p_abs = frame["pressure_a"].to_numpy(dtype=float)
        pg = p_abs - ATMOSPHERE_PA
        f = friction_from_force(frame["force"].to_numpy(dtype=float), p_abs, area)  # Zillen et al. eq. (3)
        after, sliding = _reversal_masks(x, v, REVERSAL_TRAVEL)
        if not np.any(sliding):
            raise InputError(f"{src}: the piston never slides faster than {MIN_SLIDING_SPEED*1e3:g} mm/s: no friction law to fit")
        floor = max(sensor_noise_std(frame["force"].to_numpy(dtype=float)), 1e-3)
        # the derivative window smears a reversal over +/- w/2 samples: there the estimated speed is not
        # the piston's and no friction law can be judged on it (all laws lose the same samples)
        valid = np.ones(t.size, dtype=bool)
        sgn = np.sign(v)
        for k in np.flatnonzero(sgn[1:] * sgn[:-1] < 0):
            valid[max(k - w // 2, 0):k + w // 2 + 2] = False
        out.append(Run(Path(src).name, seal_name(src), t - t[0], x, v, pg, f, after, sliding, floor, valid))
    return out

"""Operating regimes of a recorded test, computed from the recording itself.

Each regime is a boolean mask over the recording's samples. A located residual window is
attributed to the regimes it spends its time in (``attribute``), which is what points at
the missing physics: an error that lives only while the valve sits in its dead band with a
load held says "leakage", one that lives in choked-flow phases says "valve flow law", one
that follows every reversal says "friction / lag".

Definitions (the thresholds come from the plant configuration, never from the model's output):

- ``moving`` / ``at_rest``: |v| above / below ``max(friction.limit_velocity, 4 sigma_v)``
  where v is the Savitzky-Golay derivative of the recorded position and sigma_v the noise that
  derivative carries (white position noise through the filter's coefficients).
- ``opening`` / ``closing``: moving with v > 0 / v < 0 (x = 0 is the closed gate).
- ``valve_dead_band``: -zme < U - U_centre < zmd (no path open).
- ``valve_saturated``: |U - U_centre| >= valve.saturation_voltage (a path fully open);
  ``command_at_limit``: |U - U_centre| at the controller's command limit.
- ``a_choked`` / ``a_subsonic`` / ``b_choked`` / ``b_subsonic``: the open path of side A / B
  (P->A or A->T; P->B or B->T) has a downstream/upstream pressure ratio <= b / > b
  (ISO 6358, seed 000 eq. 2). Only with both chamber pressures recorded.
- ``region_closed`` / ``region_low`` / ``region_mid`` / ``region_high``: x < 2 % of stroke,
  < 1/3, < 2/3, >= 2/3 of stroke.
- ``after_reversal``: the first ``REVERSAL_SPAN`` seconds of a motion in the direction
  opposite to the previous motion.
- ``holding_under_load``: at rest while |load| exceeds the total static friction (the
  chambers, not the seals, must carry it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.signal import savgol_coeffs, savgol_filter

from compliance.model.config import PlantConfig
from compliance.validation.recorded_noise import robust_std
from compliance.validation.resampling import is_uniform, resample_uniform

VELOCITY_WINDOW = 0.051  # s; Savitzky-Golay window of the velocity estimate (quadratic)
REVERSAL_SPAN = 0.5  # s; how long "after a reversal" lasts
CLOSED_FRACTION = 0.02  # of stroke: below it the gate counts as closed
DOMINANT_FRACTION = 0.5  # a window is "in" a regime when at least half its samples are

REGIME_NAMES = (
    "moving", "at_rest", "opening", "closing",
    "valve_dead_band", "valve_saturated", "command_at_limit",
    "a_choked", "a_subsonic", "b_choked", "b_subsonic",
    "region_closed", "region_low", "region_mid", "region_high",
    "after_reversal", "holding_under_load",
)


@dataclass
class Regimes:
    """Regime masks of one recording.

    Attributes
    ----------
    time : ndarray
        Recording time stamps [s].
    masks : dict
        Regime name -> boolean array (only regimes the recorded columns allow).
    velocity : ndarray
        Smoothed velocity estimate [m/s].
    thresholds : dict
        Values used (``rest_velocity`` [m/s], ``static_friction`` [N]...).
    """

    time: np.ndarray
    masks: dict[str, np.ndarray]
    velocity: np.ndarray
    thresholds: dict = field(default_factory=dict)

    def fractions(self) -> dict[str, float]:
        """Share of the recording spent in each regime."""
        return {k: float(np.mean(v)) for k, v in self.masks.items()}


def smoothed_velocity(time: np.ndarray, position: np.ndarray, window: float = VELOCITY_WINDOW) -> tuple[np.ndarray, float]:
    """Velocity of a recorded position and the standard deviation its noise leaves in it.

    Parameters
    ----------
    time, position : ndarray
        [s], [m] (any sampling; a non-uniform recording is interpolated on its median step).
    window : float
        Savitzky-Golay window [s] (quadratic fit).

    Returns
    -------
    (ndarray, float)
        Velocity at the recording's samples [m/s]; noise standard deviation of that estimate [m/s].
    """
    time = np.asarray(time, dtype=float)
    position = np.asarray(position, dtype=float)
    uniform = is_uniform(time)
    tg, xg = (time, position) if uniform else resample_uniform(time, position)
    dt = float(np.median(np.diff(tg)))
    w = max(5, int(round(window / dt)) | 1)
    if xg.size <= w:
        v = np.gradient(xg, tg)
        return (v if uniform else np.interp(time, tg, v)), 0.0
    v = savgol_filter(xg, w, 2, deriv=1, delta=dt)
    noise = xg - savgol_filter(xg, w, 3)
    coeffs = savgol_coeffs(w, 2, deriv=1, delta=dt)
    sigma_v = robust_std(noise) * float(np.sqrt(np.sum(coeffs**2)))  # white noise through the FIR filter
    return (v if uniform else np.interp(time, tg, v)), sigma_v


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Index runs [start, end] (inclusive) where mask is True."""
    idx = np.flatnonzero(mask)
    if idx.size == 0:
        return []
    breaks = np.flatnonzero(np.diff(idx) > 1)
    starts = np.concatenate(([idx[0]], idx[breaks + 1]))
    ends = np.concatenate((idx[breaks], [idx[-1]]))
    return list(zip(starts.tolist(), ends.tolist()))


def compute_regimes(recording: pd.DataFrame, cfg: PlantConfig, load: float | str | None = None, supply_pressure: float | None = None) -> Regimes:
    """Regime masks of a recording (see the module docstring for the definitions).

    Parameters
    ----------
    recording : pandas.DataFrame
        Canonical columns; ``time`` and ``position`` required, the others optional.
    cfg : PlantConfig
        Plant the recording was taken on (dead band, stroke, friction, critical ratio).
    load : float, "curve" or None
        Closing load [N] (> 0 closes).
    supply_pressure : float, optional
        Supply pressure [Pa abs] when not recorded (default: configured).
    """
    t = recording["time"].to_numpy(dtype=float)
    x = recording["position"].to_numpy(dtype=float)
    v, sigma_v = smoothed_velocity(t, x)
    v_rest = max(cfg.p("friction.limit_velocity"), 4.0 * sigma_v)
    masks: dict[str, np.ndarray] = {}
    moving = np.abs(v) > v_rest
    masks["moving"] = moving
    masks["at_rest"] = ~moving
    masks["opening"] = moving & (v > 0)
    masks["closing"] = moving & (v < 0)
    thresholds = {"rest_velocity": v_rest, "velocity_noise": sigma_v}
    if "valve_command" in recording:
        u = recording["valve_command"].to_numpy(dtype=float) - cfg.p("valve.centre_voltage")
        zmd, zme = cfg.p("valve.dead_zone_positive"), abs(cfg.p("valve.dead_zone_negative"))
        masks["valve_dead_band"] = (u < zmd) & (u > -zme)
        masks["valve_saturated"] = np.abs(u) >= cfg.p("valve.saturation_voltage")
        lim = cfg.p("valve.command_limit")
        masks["command_at_limit"] = np.abs(u) >= lim * (1.0 - 1e-6)
        if "pressure_a" in recording and "pressure_b" in recording:
            pa = recording["pressure_a"].to_numpy(dtype=float)
            pb = recording["pressure_b"].to_numpy(dtype=float)
            if "supply_pressure" in recording:
                ps = recording["supply_pressure"].to_numpy(dtype=float)
            else:
                ps = np.full(t.shape, supply_pressure if supply_pressure else cfg.p("air.supply_pressure"))
            patm = cfg.p("air.atmospheric_pressure")
            b = cfg.p("valve.critical_pressure_ratio")
            pos, neg = u >= zmd, u <= -zme
            # pressure ratio p_down/p_up of the open path on each side (seed 000 eq. 2)
            with np.errstate(divide="ignore", invalid="ignore"):
                ratio_a = np.where(pos, np.minimum(pa, ps) / np.maximum(pa, ps), np.minimum(pa, patm) / np.maximum(pa, patm))
                ratio_b = np.where(neg, np.minimum(pb, ps) / np.maximum(pb, ps), np.minimum(pb, patm) / np.maximum(pb, patm))
            open_ = pos | neg
            masks["a_choked"] = open_ & (ratio_a <= b)
            masks["a_subsonic"] = open_ & (ratio_a > b)
            masks["b_choked"] = open_ & (ratio_b <= b)
            masks["b_subsonic"] = open_ & (ratio_b > b)
            thresholds["critical_pressure_ratio"] = b
    stroke = cfg.p("cylinder.stroke")
    masks["region_closed"] = x < CLOSED_FRACTION * stroke
    masks["region_low"] = (x >= CLOSED_FRACTION * stroke) & (x < stroke / 3.0)
    masks["region_mid"] = (x >= stroke / 3.0) & (x < 2.0 * stroke / 3.0)
    masks["region_high"] = x >= 2.0 * stroke / 3.0
    after = np.zeros(t.shape, dtype=bool)
    last_sign = 0
    for a, b_ in _runs(moving):
        sign = int(np.sign(np.mean(v[a:b_ + 1])))
        if last_sign and sign and sign != last_sign:
            after |= (t >= t[a]) & (t <= t[a] + REVERSAL_SPAN)
        last_sign = sign or last_sign
    masks["after_reversal"] = after
    n_fr = 2.0 if cfg.options["cylinder.arrangement"] == "tandem" else 1.0  # friction parameters are per cylinder
    f_static = n_fr * cfg.p("friction.static_force")
    if load == "curve" and cfg.load_curve is not None:
        f_load = np.interp(x, *cfg.load_curve_forces())
    elif isinstance(load, (int, float)) and math.isfinite(load):
        f_load = np.full(t.shape, float(load))
    else:
        f_load = np.zeros(t.shape)
    masks["holding_under_load"] = ~moving & (np.abs(f_load) > f_static)
    thresholds["static_friction"] = f_static
    ordered = {k: masks[k] for k in REGIME_NAMES if k in masks}
    return Regimes(time=t, masks=ordered, velocity=v, thresholds=thresholds)


def attribute(regimes: Regimes, start: int, end: int) -> tuple[dict[str, float], list[str]]:
    """Share of samples ``start..end`` (inclusive) in each regime, and the dominant regimes.

    Returns
    -------
    (dict, list)
        Regime -> fraction of the window (0..1); names with fraction >= ``DOMINANT_FRACTION``,
        largest first.
    """
    sl = slice(int(start), int(end) + 1)
    frac = {k: float(np.mean(m[sl])) for k, m in regimes.masks.items()}
    dominant = sorted((k for k, f in frac.items() if f >= DOMINANT_FRACTION), key=lambda k: -frac[k])
    return frac, dominant

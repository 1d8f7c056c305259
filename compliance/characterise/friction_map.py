"""Friction-velocity maps from constant-speed runs (seed 000 sec. 3, fig. 3; Zillen bench data).

The map is the one the plant uses (reference-plant.md, friction; the steady state of
``compliance.physics.friction.stribeck_map``), per direction d = sign(v) if asymmetric:

    F(v) = d * [F_C,d + k_p * p_gauge + (F_S,d - F_C,d) * exp(-|v|/v_s,d) + b_d * |v|]

with the optional pressure-dependent Coulomb term F_C = F_C0 + k_p * p_gauge (seal lip load
grows with the pressure behind it). Samples are binned by speed per run and direction, the
median friction of each well-populated bin is one observation, and the map is fitted to
those by bounded least squares. Standard errors are s^2 (J^T J)^-1 on the bins.

A term is fitted only when the runs can show it; otherwise it is fixed at zero and the
result says why: the viscous slope needs populated speeds spanning a factor >= 3, the
Stribeck decay a factor >= 10 with >= 5 populated bins, the pressure term >= 2 pressures
at least 0.5 bar apart.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.optimize import least_squares

from compliance.characterise.friction_runs import FrictionRun, friction_from_force, piston_area, prepare_run
from compliance.characterise.friction_runs import stribeck_friction, synthetic_friction_run
from compliance.errors import InputError
from compliance.physics.friction import stribeck_magnitude_array

__all__ = [  # the runs are prepared beside this module and stay importable from it
    "FrictionCharacterisation", "FrictionFit", "FrictionRun", "bin_friction", "characterise_friction", "fit_friction_map",
    "friction_from_force", "piston_area", "prepare_run", "stribeck_friction", "synthetic_friction_run",
]

VISCOUS_SPAN = 3.0  # populated speed range (max/min) needed to fit b
STRIBECK_SPAN = 10.0  # ... and to fit the Stribeck decay
STRIBECK_BINS = 5
PRESSURE_SPREAD = 0.5e5  # [Pa] needed between the lowest and highest run pressure to fit k_p


def _directions(asymmetric: bool):
    return (("pos", 1.0), ("neg", -1.0)) if asymmetric else (("", 0.0),)


def _pname(base: str, d: str) -> str:
    return f"{base}_{d}" if d else base


@dataclass(frozen=True)
class FrictionFit:
    """A fitted friction map. ``params`` in SI; ``fixed`` says which terms were not fitted and why."""

    model: str  # "pressure-independent" or "pressure-dependent"
    asymmetric: bool
    params: dict
    stderr: dict
    units: dict
    fixed: dict
    rms_bins: float  # [N]
    rms_samples: float  # [N], over the samples of the fitted bins
    n_bins: int
    n_samples: int
    speed_range: dict = field(default_factory=dict)  # direction -> (min, max) populated speed [m/s]

    def magnitude(self, speed, pressure_gauge, direction: str = ""):
        """|F| at ``speed`` [m/s] >= 0 and gauge pressure [Pa] for a direction ('pos'/'neg'/'') [N]."""
        d = direction if self.asymmetric else ""
        g = self.params
        s = np.asarray(speed, dtype=float)
        coulomb = g[_pname("coulomb", d)] + g.get("pressure_coefficient", 0.0) * np.asarray(pressure_gauge, dtype=float)
        viscous = g[_pname("viscous", d)] * s
        drop = g[_pname("stribeck_drop", d)]
        if drop == 0.0:  # a Stribeck term that was not fitted has drop 0 and velocity NaN
            return coulomb + viscous
        return stribeck_magnitude_array(s, coulomb + drop, coulomb, g[_pname("stribeck_velocity", d)]) + viscous

    def predict(self, velocity, pressure_gauge=0.0):
        """Friction force at ``velocity`` [m/s] and gauge pressure [Pa] [N] (0 at v = 0)."""
        v = np.asarray(velocity, dtype=float)
        s = np.abs(v)
        if self.asymmetric:
            mag = np.where(v >= 0, self.magnitude(s, pressure_gauge, "pos"), self.magnitude(s, pressure_gauge, "neg"))
        else:
            mag = self.magnitude(s, pressure_gauge)
        return np.sign(v) * mag

    def to_dict(self) -> dict:
        """JSON-ready summary (SI units)."""
        return {
            "model": self.model, "asymmetric": self.asymmetric, "params": self.params, "stderr": self.stderr,
            "units": self.units, "fixed": self.fixed, "rms_bins_N": self.rms_bins, "rms_samples_N": self.rms_samples,
            "n_bins": self.n_bins, "n_samples": self.n_samples,
            "speed_range_m_per_s": {k: list(v) for k, v in self.speed_range.items()},
        }


def bin_friction(velocity, friction, pressure_gauge, group, *, steady=None, v_min=1e-3, bins_per_decade=10,
                 min_count=10, min_fraction=0.0) -> pd.DataFrame:
    """Median friction per (run, direction, logarithmic speed bin).

    Parameters
    ----------
    velocity, friction, pressure_gauge : array_like
        Per sample: [m/s], [N], [Pa gauge].
    group : array_like
        Run label per sample (bins never mix runs).
    steady : array_like of bool, optional
        Samples at constant speed (see ``prepare_run``); others are not binned.
    v_min : float
        Speeds below this are not binned [m/s] (stick / presliding, not a map point).
    bins_per_decade : int
        Logarithmic bin density.
    min_count, min_fraction : int, float
        A bin is ``populated`` (a map point) if it holds >= ``min_count`` steady samples and
        >= ``min_fraction`` of its run-direction's binned samples.

    Returns
    -------
    pandas.DataFrame
        One row per bin: ``group``, ``direction`` (+1/-1), ``bin``, ``speed`` [m/s],
        ``friction`` [N] (signed), ``pressure_gauge`` [Pa], ``count``, ``populated``;
        ``.attrs["sample_bin"]`` holds each sample's bin row (-1 if not binned).
    """
    v = np.asarray(velocity, dtype=float)
    frame = pd.DataFrame({
        "group": np.asarray(group), "direction": np.sign(v), "speed": np.abs(v),
        "friction": np.asarray(friction, dtype=float), "pressure_gauge": np.asarray(pressure_gauge, dtype=float),
    })
    keep = frame["speed"] >= v_min
    if steady is not None:
        keep &= np.asarray(steady, dtype=bool)
    frame["bin"] = -1
    frame.loc[keep, "bin"] = np.floor(np.log10(frame.loc[keep, "speed"] / v_min) * bins_per_decade).astype(int)
    grouped = frame[keep].groupby(["group", "direction", "bin"], sort=True)
    bins = grouped.agg(speed=("speed", "median"), friction=("friction", "median"),
                       pressure_gauge=("pressure_gauge", "mean"), count=("speed", "size")).reset_index()
    per_run = bins.groupby(["group", "direction"])["count"].transform("sum")
    bins["populated"] = (bins["count"] >= min_count) & (bins["count"] >= min_fraction * per_run)
    key = pd.MultiIndex.from_frame(bins[["group", "direction", "bin"]])
    sample_key = pd.MultiIndex.from_frame(frame[["group", "direction", "bin"]])
    sample_bin = key.get_indexer(sample_key)
    sample_bin[~keep.to_numpy()] = -1
    bins.attrs["sample_bin"] = sample_bin
    return bins


def fit_friction_map(bins: pd.DataFrame, *, asymmetric=True, pressure_dependent=False, samples=None) -> FrictionFit:
    """Fit the friction map to the populated bins of ``bin_friction``.

    Parameters
    ----------
    bins : pandas.DataFrame
        Output of ``bin_friction``.
    asymmetric : bool
        Separate parameters for each direction (a shared pressure coefficient).
    pressure_dependent : bool
        F_C = F_C0 + k_p * p_gauge with ``pressure_coefficient`` k_p [N/Pa].
    samples : (velocity, friction, pressure_gauge), optional
        The binned samples, for the sample-level residual RMS.

    Returns
    -------
    FrictionFit
    """
    used = bins[bins["populated"]]
    if used.empty:
        raise InputError("no populated speed bins: the runs have no constant-speed part above the minimum speed")
    names, x0, lo, hi, units, fixed, ranges = _free_terms(used, asymmetric, pressure_dependent)
    speed = used["speed"].to_numpy()
    direction = used["direction"].to_numpy()
    pg = used["pressure_gauge"].to_numpy()
    target = used["friction"].to_numpy()

    def build(x) -> FrictionFit:
        p = dict(zip(names, map(float, x)))
        for d, _ in _directions(asymmetric):
            p.setdefault(_pname("stribeck_drop", d), 0.0)
            p.setdefault(_pname("stribeck_velocity", d), 1.0)  # irrelevant when the drop is 0
            p.setdefault(_pname("viscous", d), 0.0)
        if pressure_dependent:
            p.setdefault("pressure_coefficient", 0.0)
        return FrictionFit("", asymmetric, p, {}, {}, {}, 0.0, 0.0, 0, 0)

    def resid(x):
        return build(x).predict(direction * speed, pg) - target

    x0 = np.clip(np.array(x0), np.array(lo) + 1e-12, np.array(hi) - 1e-12)
    res = least_squares(resid, x0, bounds=(lo, hi), x_scale="jac", method="trf")
    m, k = target.size, len(names)
    rss = float(res.fun @ res.fun)
    cov = np.full((k, k), np.inf)
    if m > k:
        try:
            cov = np.linalg.inv(res.jac.T @ res.jac) * rss / (m - k)
        except np.linalg.LinAlgError:
            pass
    params = build(res.x).params
    stderr = dict(zip(names, map(float, np.sqrt(np.clip(np.diag(cov), 0.0, None)))))
    for d, _ in _directions(asymmetric):
        params[_pname("static", d)] = params[_pname("coulomb", d)] + params[_pname("stribeck_drop", d)]
        if _pname("stribeck_drop", d) in fixed:
            params[_pname("stribeck_velocity", d)] = float("nan")
    if asymmetric:
        _direction_split(params, stderr, units, cov, names)
    rms_samples, n_samples = float("nan"), int(used["count"].sum())
    if samples is not None:
        rms_samples, n_samples = _sample_rms(build(res.x), bins, samples)
    return FrictionFit(
        model="pressure-dependent" if pressure_dependent else "pressure-independent", asymmetric=asymmetric,
        params=params, stderr=stderr, units={k: units[k] for k in params if k in units}, fixed=fixed,
        rms_bins=math.sqrt(rss / m), rms_samples=rms_samples, n_bins=m, n_samples=n_samples, speed_range=ranges,
    )


def _free_terms(used: pd.DataFrame, asymmetric: bool, pressure_dependent: bool):
    """The map's terms the populated bins can show: names, start values, bounds, units; the rest fixed (why).

    Returns
    -------
    tuple
        (names, x0, lower, upper, units, fixed {name: reason}, populated speed range per direction).
    """
    names, x0, lo, hi, units = [], [], [], [], {}
    fixed, ranges = {}, {}
    for d, sgn in _directions(asymmetric):
        part = used if not d else used[used["direction"] == sgn]
        if part.empty:
            raise InputError(f"no populated speed bins in the {'positive' if sgn > 0 else 'negative'} direction")
        smin, smax = float(part["speed"].min()), float(part["speed"].max())
        ranges[d or "both"] = (smin, smax)
        mag = float(np.median(np.abs(part["friction"])))
        names.append(_pname("coulomb", d)); x0.append(mag); lo.append(-np.inf); hi.append(np.inf)
        span = smax / smin
        distinct = part["bin"].nunique()
        if span >= STRIBECK_SPAN and distinct >= STRIBECK_BINS:
            names += [_pname("stribeck_drop", d), _pname("stribeck_velocity", d)]
            x0 += [0.1 * abs(mag) + 1e-3, 2.0 * smin]; lo += [0.0, 0.1 * smin]; hi += [np.inf, smax]
        else:
            why = f"populated speeds {smin:.3g}-{smax:.3g} m/s span x{span:.2g} (< {STRIBECK_SPAN:g} or < {STRIBECK_BINS} bins)"
            fixed[_pname("stribeck_drop", d)] = why
        if span >= VISCOUS_SPAN:
            names.append(_pname("viscous", d)); x0.append(0.0); lo.append(0.0); hi.append(np.inf)
        else:
            fixed[_pname("viscous", d)] = f"populated speeds {smin:.3g}-{smax:.3g} m/s span x{span:.2g} (< {VISCOUS_SPAN:g})"
        units.update({_pname("coulomb", d): "N", _pname("static", d): "N", _pname("stribeck_drop", d): "N",
                      _pname("stribeck_velocity", d): "m/s", _pname("viscous", d): "N*s/m"})
    if pressure_dependent:
        spread = float(used["pressure_gauge"].max() - used["pressure_gauge"].min())
        if spread >= PRESSURE_SPREAD:
            names.append("pressure_coefficient"); x0.append(0.0); lo.append(-np.inf); hi.append(np.inf)
            units["pressure_coefficient"] = "N/Pa"
        else:
            fixed["pressure_coefficient"] = f"run pressures span {spread / 1e5:.2g} bar (< {PRESSURE_SPREAD / 1e5:g} bar)"
    return names, x0, lo, hi, units, fixed, ranges


def _direction_split(params: dict, stderr: dict, units: dict, cov: np.ndarray, names: list) -> None:
    """Add ``coulomb_mean`` and ``direction_offset`` (with standard errors) to an asymmetric fit.

    The two directions' mean is the seal's Coulomb level; half their difference is a
    direction-independent force (sensor zero, p*A area error) seen as asymmetry.
    """
    ip, ineg = names.index("coulomb_pos"), names.index("coulomb_neg")
    for key, sign in (("coulomb_mean", 1.0), ("direction_offset", -1.0)):
        params[key] = 0.5 * (params["coulomb_pos"] + sign * params["coulomb_neg"])
        block = cov[np.ix_([ip, ineg], [ip, ineg])]
        var = 0.25 * (block[0, 0] + block[1, 1] + 2.0 * sign * block[0, 1]) if np.all(np.isfinite(block)) else np.inf
        stderr[key] = float(np.sqrt(max(var, 0.0)))
        units[key] = "N"


def _sample_rms(fit: FrictionFit, bins: pd.DataFrame, samples) -> tuple[float, int]:
    """RMS residual [N] over the samples of the populated bins, and their number."""
    sv, sf, sp = (np.asarray(a, dtype=float) for a in samples)
    sample_bin = bins.attrs.get("sample_bin")
    mask = np.isin(sample_bin, np.flatnonzero(bins["populated"].to_numpy())) if sample_bin is not None else np.ones(sv.size, bool)
    r = fit.predict(sv[mask], sp[mask]) - sf[mask]
    return float(np.sqrt(np.mean(r**2))), int(mask.sum())


@dataclass(frozen=True)
class FrictionCharacterisation:
    """Both fits over all runs, one fit per run, and the bins they used."""

    area: float
    fits: dict  # "pressure-independent" / "pressure-dependent" -> FrictionFit
    per_run: tuple  # (name, mean gauge pressure [Pa], FrictionFit)
    bins: pd.DataFrame
    runs: tuple

    def to_dict(self) -> dict:
        """JSON-ready summary (SI units)."""
        return {
            "area_m2": self.area,
            "fits": {k: f.to_dict() for k, f in self.fits.items()},
            "per_run": [{"run": n, "pressure_gauge_Pa": p, "fit": f.to_dict()} for n, p, f in self.per_run],
        }


def characterise_friction(runs, *, asymmetric=True, v_min=1e-3, bins_per_decade=10, min_count=10,
                          min_fraction=0.0) -> FrictionCharacterisation:
    """Fit the friction map to several runs of one seal (e.g. all its pressures) at once.

    Parameters
    ----------
    runs : sequence of FrictionRun
    asymmetric : bool
        Separate parameters per direction.
    v_min, bins_per_decade, min_count, min_fraction
        Binning, see ``bin_friction``.

    Returns
    -------
    FrictionCharacterisation
        ``fits["pressure-independent"]`` and, with >= 2 pressures, ``fits["pressure-dependent"]``.
    """
    if not runs:
        raise InputError("friction characterisation needs at least one run")
    v = np.concatenate([r.velocity for r in runs])
    f = np.concatenate([r.friction for r in runs])
    p = np.concatenate([r.pressure_gauge for r in runs])
    g = np.concatenate([np.full(r.velocity.size, i) for i, r in enumerate(runs)])
    steady = np.concatenate([r.steady for r in runs])
    _check_speeds(np.abs(v), steady, v_min)
    opts = dict(v_min=v_min, bins_per_decade=bins_per_decade, min_count=min_count, min_fraction=min_fraction)
    bins = bin_friction(v, f, p, g, steady=steady, **opts)
    fits = {"pressure-independent": fit_friction_map(bins, asymmetric=asymmetric, samples=(v, f, p))}
    pressures = [r.mean_pressure_gauge for r in runs]
    if len(runs) > 1 and max(pressures) - min(pressures) >= PRESSURE_SPREAD:
        fits["pressure-dependent"] = fit_friction_map(bins, asymmetric=asymmetric, pressure_dependent=True, samples=(v, f, p))
    per_run = []
    for r in runs:
        b = bin_friction(r.velocity, r.friction, r.pressure_gauge, np.zeros(r.velocity.size), steady=r.steady, **opts)
        fit = fit_friction_map(b, asymmetric=asymmetric, samples=(r.velocity, r.friction, r.pressure_gauge))
        per_run.append((r.name, r.mean_pressure_gauge, fit))
    bins["run"] = [runs[int(i)].name for i in bins["group"]]
    return FrictionCharacterisation(runs[0].area, fits, tuple(per_run), bins, tuple(runs))


def _check_speeds(speed, steady, v_min: float) -> None:
    """Name the option that leaves no map point: no constant-speed part, or all below ``v_min``."""
    if not np.any(steady & (speed > 0)):
        raise InputError("no constant-speed part in the runs: the speed changes by more than 10 % over every "
                         "velocity window; the map needs strokes at constant speed (a shorter --window may find them)")
    fastest = float(np.max(speed[steady]))
    if fastest < v_min:
        raise InputError(f"--min-speed {v_min * 1e3:g} mm/s is above every constant-speed part of the runs "
                         f"(fastest {fastest * 1e3:.3g} mm/s); give a lower --min-speed")

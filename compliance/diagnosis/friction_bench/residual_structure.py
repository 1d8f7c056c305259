"""What a fitted friction law leaves on the bench: structure named and modelled empirically.

The residual of the best friction law (``friction_bench.fit``) is regressed, over all runs of a seal,
on a dictionary of physical shapes by the same sparse forward selection as the servo's
empirical term (``evidence.empirical_force.sparse_fit``, BIC stopping rule):

- position along the stroke: friction that varies with position (sign(v) times hat functions of
  x over ``POSITION_BINS`` bins of the travelled range) and a direction-independent force of
  position (a hose or spring; hat functions alone);
- direction asymmetry: a force that only acts in one direction (the sliding samples with v > 0);
- velocity shape: sign(v) sqrt(|v|/v_ref) and sign(v) (|v|/v_ref)^2 besides the viscous term;
- pressure shape: sign(v) (p_g / 1 bar)^2 (a non-linear rise of the friction with pressure);
- run-to-run differences: one constant per run beyond the common bias, a drift linear in time
  within a run, a friction level of its own per run (a pressure dependence the law does not
  follow) and a friction level drifting linearly in time within a run.

The terms are reported in words with their size and what they remove; the law plus the terms
is the empirical model of the seal (labelled an empirical suggestion, not a declared effect).
"""

from __future__ import annotations

import math

import numpy as np

from compliance.diagnosis.evidence.empirical_force import sparse_fit
from compliance.presentation.numbers import fmt_si

POSITION_BINS = 8  # hat functions along the travelled range
V_REF = 0.01  # m/s; reference speed of the velocity shapes
BAR = 1e5
MAX_TERMS = 8  # a position map needs several hat functions
MIN_SHARE = 0.02  # share of what is left a term must remove (one hat function covers an eighth of the stroke)


def _hats(x: np.ndarray, lo: float, hi: float, k: int) -> list[np.ndarray]:
    centres = np.linspace(lo, hi, k)
    w = (hi - lo) / (k - 1)
    return [np.clip(1.0 - np.abs(x - c) / w, 0.0, None) for c in centres]


def _features(runs) -> tuple[dict[str, np.ndarray], dict[str, str]]:
    x = np.concatenate([r.position[r.valid] for r in runs])
    v = np.concatenate([r.velocity[r.valid] for r in runs])
    p = np.concatenate([r.pressure_gauge[r.valid] for r in runs])
    sgn = np.sign(v)
    lo, hi = float(np.percentile(x, 1)), float(np.percentile(x, 99))
    feats, words = {}, {}
    for j, h in enumerate(_hats(x, lo, hi, POSITION_BINS)):
        xc = (lo + j * (hi - lo) / (POSITION_BINS - 1)) * 1e3
        feats[f"friction_at_{j}"] = sgn * h
        words[f"friction_at_{j}"] = f"friction {{sign}} by {{size}} around x = {xc:.0f} mm"
        feats[f"force_at_{j}"] = h
        words[f"force_at_{j}"] = f"a direction-independent force of {{value}} around x = {xc:.0f} mm"
    feats["forward_only"] = (v > 0).astype(float)
    words["forward_only"] = "a force of {value} acting only while moving forward (direction asymmetry)"
    feats["sqrt_speed"] = sgn * np.sqrt(np.abs(v) / V_REF)
    words["sqrt_speed"] = f"friction {{sign}} with the square root of speed ({{size}} at {V_REF*1e3:.0f} mm/s)"
    feats["speed_squared"] = sgn * (v / V_REF) ** 2
    words["speed_squared"] = f"friction {{sign}} with the square of speed ({{size}} at {V_REF*1e3:.0f} mm/s)"
    feats["pressure_squared"] = sgn * (p / BAR) ** 2
    words["pressure_squared"] = "friction {sign} with the square of the gauge pressure ({size} at 100 kPa, \u00d7 49 at 700 kPa)"
    start = 0
    for r in runs:
        m = int(r.valid.sum())
        f = np.zeros(x.size)
        f[start:start + m] = 1.0
        feats[f"offset_{r.name}"] = f
        words[f"offset_{r.name}"] = f"a constant force of {{value}} in run {r.name} only (run-to-run offset)"
        t = r.time[r.valid]
        g = np.zeros(x.size)
        g[start:start + m] = (t - t[0]) / max(t[-1] - t[0], 1e-9)
        feats[f"drift_{r.name}"] = g
        words[f"drift_{r.name}"] = f"a force drifting by {{value}} over run {r.name} (drift during the run)"
        feats[f"level_{r.name}"] = f * sgn
        words[f"level_{r.name}"] = f"friction {{sign}} by {{size}} in run {r.name} (a pressure dependence the law misses)"
        feats[f"friction_drift_{r.name}"] = g * sgn
        words[f"friction_drift_{r.name}"] = f"friction {{rising}} by {{size}} over run {r.name} (drift of the friction during the run)"
        start += m
    return feats, words


def _words(template: str, c: float) -> str:
    return template.format(sign="higher" if c > 0 else "lower", rising="rising" if c > 0 else "falling",
                           size=fmt_si(abs(c), "N", digits=2),
                           value=("+" if c >= 0 else "") + fmt_si(c, "N", digits=2))


def friction_structure(runs, law_fit) -> dict:
    """Structure the friction law leaves, found by sparse regression of its residual.

    Parameters
    ----------
    runs : list of friction_runs.Run
        One seal's runs.
    law_fit : friction_fit.LawFit
        The law whose residuals (per run, over ``Run.valid``) are examined.

    Returns
    -------
    dict
        ``label``, ``terms`` (feature, coefficient [N], words), ``words``, ``rms_before`` and
        ``rms_after`` [N], ``improvement``, ``rms_after_in_noise`` (RMS after / force noise).
    """
    target = np.concatenate(law_fit.residuals)
    feats, words = _features(runs)
    fit = sparse_fit(target, feats, max_terms=MAX_TERMS, min_share=MIN_SHARE)
    for t in fit["terms"]:
        t["words"] = _words(words[t["feature"]], t["coefficient"])
    noise = float(np.median([r.floor for r in runs]))
    text = ("; ".join(t["words"] for t in fit["terms"]) if fit["terms"] else "no simple structure")
    return {"label": "empirical suggestion, not a declared effect", "terms": fit["terms"],
            "words": (f"What the law leaves: {text}. Modelled, the residual falls from {fmt_si(fit['rms_before'], 'N')} to "
                      f"{fmt_si(fit['rms_after'], 'N')} ({fit['rms_after'] / noise:.1f} times the force noise)."),
            "rms_before": fit["rms_before"], "rms_after": fit["rms_after"], "improvement": fit["improvement"],
            "rms_after_in_noise": fit["rms_after"] / noise if noise > 0 else math.inf}


__all__ = ["friction_structure"]

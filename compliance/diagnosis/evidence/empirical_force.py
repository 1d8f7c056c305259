"""Outside the library: the missing force a recording implies, regressed sparsely on physical features.

When no declared effect explains a recording, the diagnosis still estimates the form of what
is missing. Along the recorded trajectory Newton's law of the piston (seed 000 eq. 6),

    M a = F_p(p_A, p_B) - F_load(x) - F_f(v, p) + dF,

gives the force the model lacks, dF, from the measured pressures and the smoothed position
(velocity and acceleration by Savitzky-Golay derivatives), with the (best fitted) model's own
load and friction map. Only samples in motion are used (|v| > ``MOVING_SPEED``): at rest the
static friction takes up any force and dF is not determined. dF is then regressed on a small
dictionary of physical features by greedy forward selection (sparse regression, as in
Brunton et al. 2016, with a BIC stopping rule): a constant, position from the start point,
velocity, direction of motion, direction times the mean chamber gauge pressure, direction
times a decay over the first ``REVERSAL_TIME`` after a reversal, and the chamber pressures.
A term joins only when it lowers BIC by ``SIGNIFICANCE`` and removes ``MIN_SHARE`` of what is
left. The result is an *empirical suggestion*, not a declared effect: its form in words, its
coefficients, and how much of the implied force discrepancy it removes.
"""

from __future__ import annotations

import math

import numpy as np

from compliance.model.assembly import friction_level_at
from compliance.model.plant_vector import load_curve_arrays, parameter_vector
from compliance.model.rest_state import load_force, pneumatic_forces
from compliance.validation.replay_conditions import load_at_start
from compliance.model.vector_slots import P_BV, P_FC, P_FS, P_MASS, P_NFR, P_PATM, P_VS
from compliance.physics.friction import stribeck_map

MOVING_SPEED = 2e-3  # m/s; below it static friction absorbs any force
REVERSAL_TIME = 0.1  # s; decay time of the after-reversal feature (pre-sliding, breakaway transients)
SIGNIFICANCE = 10.0  # BIC decrease a term must bring (Kass & Raftery 1995: strong)
MIN_SHARE = 0.05  # share of the remaining sum of squares a term must remove
MAX_TERMS = 3
MIN_SAMPLES = 200
# what the estimator itself produces on a correct model's recording (velocity lag, breakaway)
ARTEFACT_FEATURES = ("velocity", "direction", "after_reversal")


def _features(x, v, pa, pb, t, x0, patm) -> dict[str, np.ndarray]:
    sgn = np.sign(v)
    rev = np.zeros_like(t)
    last = t[0] - 10.0
    for k in range(1, t.size):
        if sgn[k] != 0 and sgn[k] != sgn[k - 1]:
            last = t[k]
        rev[k] = t[k] - last
    pm = 0.5 * (pa + pb) - patm
    return {
        "constant": np.ones_like(x),
        "position": x - x0,
        "velocity": v,
        "direction": sgn,
        "direction*pressure": sgn * pm,
        "after_reversal": sgn * np.exp(-rev / REVERSAL_TIME),
        "pressure_a": pa - patm,
        "pressure_b": pb - patm,
    }


WORDS = {
    "constant": lambda c: f"a constant extra {'opening' if c > 0 else 'closing'} force of {abs(c):.0f} N (a load error)",
    "position": lambda c: (f"an extra force proportional to position, {abs(c)/1e3:.3g} N/mm "
                           f"({'opening' if c > 0 else 'closing'} as the position grows; a load stiffness)"),
    "velocity": lambda c: f"a force proportional to velocity, {-c:.3g} N*s/m of {'extra' if c < 0 else 'less'} viscous friction",
    "direction": lambda c: f"{'extra' if c < 0 else 'less'} Coulomb friction of {abs(c):.0f} N opposing the motion",
    "direction*pressure": lambda c: (f"friction {'rising' if c < 0 else 'falling'} with the mean chamber pressure, "
                                     f"{abs(c)*1e5:.3g} N/bar"),
    "after_reversal": lambda c: (f"a force of {abs(c):.0f} N {'against' if c < 0 else 'with'} the motion just after each "
                                 f"reversal, decaying over {REVERSAL_TIME*1e3:.0f} ms"),
    "pressure_a": lambda c: f"a force of {c*1e5:.3g} N per bar of side-A gauge pressure (an area error on side A)",
    "pressure_b": lambda c: f"a force of {c*1e5:.3g} N per bar of side-B gauge pressure (an area error on side B)",
}


def sparse_fit(target: np.ndarray, features: dict[str, np.ndarray], max_terms: int = MAX_TERMS,
               min_share: float = MIN_SHARE) -> dict:
    """Greedy forward selection of features (least squares, BIC stopping rule).

    Returns
    -------
    dict
        ``terms`` (list of ``{feature, coefficient}``), ``rms_before``, ``rms_after`` [target units],
        ``improvement`` (share of the sum of squares removed).
    """
    n = target.size
    chosen: list[str] = []
    rss0 = float(target @ target)
    rss = rss0
    coef = np.zeros(0)

    def bic(r, k):
        return n * math.log(max(r, 1e-300) / n) + k * math.log(n)

    while len(chosen) < max_terms:
        best = None
        for name, f in features.items():
            if name in chosen or not np.any(f):
                continue
            a = np.column_stack([features[c] for c in chosen] + [f])
            c, *_ = np.linalg.lstsq(a, target, rcond=None)
            r = float(np.sum((target - a @ c) ** 2))
            if best is None or r < best[0]:
                best = (r, name, c)
        if best is None:
            break
        r, name, c = best
        if bic(rss, len(chosen)) - bic(r, len(chosen) + 1) < SIGNIFICANCE or rss - r < min_share * rss:
            break
        chosen.append(name)
        rss, coef = r, c
    return {"terms": [{"feature": f, "coefficient": float(v)} for f, v in zip(chosen, coef)],
            "rms_before": math.sqrt(rss0 / max(n, 1)), "rms_after": math.sqrt(rss / max(n, 1)),
            "improvement": 0.0 if rss0 <= 0 else 1.0 - rss / rss0}


def implied_force(cfg, setup) -> tuple[np.ndarray, dict, np.ndarray]:
    """Missing force dF [N] along the recording (opening positive), the features, and the moving mask."""
    st = setup.states
    if "pressure_a" not in st or "pressure_b" not in st:
        return np.zeros(0), {}, np.zeros(0, bool)
    P = parameter_vector(cfg, load=load_at_start(cfg, setup.load, setup.initial_position))
    lx, ly = load_curve_arrays(cfg)
    t = setup.time
    x, v = st["position"], st["velocity"]
    pa, pb = st["pressure_a"], st["pressure_b"]
    acc = np.gradient(v, t)
    patm = P[P_PATM]
    df = np.empty(t.size)
    for k in range(t.size):
        f1, f2 = pneumatic_forces(P, pa[k], pb[k])
        rise = friction_level_at(P, float(x[k]), float(pa[k]), float(pb[k]))  # the effects' friction levels, as plant_rhs
        fs, fc = P[P_FS] * rise, P[P_FC] * rise
        ff = P[P_NFR] * stribeck_map(v[k], fs, fc, P[P_VS], P[P_BV])
        df[k] = P[P_MASS] * acc[k] - (f1 + f2) + load_force(P, x[k], lx, ly) + ff
    moving = np.abs(v) > MOVING_SPEED
    return df, _features(x, v, pa, pb, t, setup.initial_position, patm), moving


def _null_artefact(cfg, null_setup) -> dict[str, float]:
    """Feature coefficients the estimator finds on the nominal model's own recording of the test.

    The estimate of dF has artefacts of its own (the smoothed velocity lags at reversals, the
    LuGre breakaway exceeds the map): a correct model leaves them too, so they are regressed
    there on the motion features (``ARTEFACT_FEATURES``) and subtracted before the sparse search.
    """
    df, feats, moving = implied_force(cfg, null_setup)
    if moving.sum() < MIN_SAMPLES:
        return {}
    names = list(ARTEFACT_FEATURES)
    a = np.column_stack([feats[k][moving] for k in names])
    c, *_ = np.linalg.lstsq(a, df[moving], rcond=None)
    return dict(zip(names, c))


def empirical_term(cfg, setup, null_setup=None) -> dict | None:
    """The empirical suggestion for a recording (None when it cannot be estimated).

    Parameters
    ----------
    cfg : PlantConfig
        The (best fitted) model whose force balance is checked.
    setup : ReplaySetup
        The recording.
    null_setup : ReplaySetup, optional
        The same test recorded by ``cfg`` itself (``evidence.residuals.null_recording``): the estimator's
        own artefacts found there are removed first.

    Returns
    -------
    dict or None
        ``label`` ("empirical suggestion, not a declared effect"), ``quantity`` (what was regressed),
        ``terms`` (feature, coefficient, words), ``words`` (one sentence), ``rms_before`` and
        ``rms_after`` [N], ``improvement`` (share of the discrepancy's sum of squares removed),
        ``samples`` (moving samples used).
    """
    df, feats, moving = implied_force(cfg, setup)
    if moving.sum() < MIN_SAMPLES:
        return None
    art = _null_artefact(cfg, null_setup) if null_setup is not None else {}
    target = df[moving] - sum((c * feats[k][moving] for k, c in art.items()), np.zeros(int(moving.sum())))
    fit = sparse_fit(target, {k: f[moving] for k, f in feats.items()})
    for term in fit["terms"]:
        term["words"] = WORDS[term["feature"]](term["coefficient"])
    if fit["terms"]:
        words = ("An extra force acting while the piston moves: " + "; ".join(t["words"] for t in fit["terms"])
                 + f". It removes {100*fit['improvement']:.0f} % of the force discrepancy the recording implies "
                 f"(RMS {fit['rms_before']:.0f} N -> {fit['rms_after']:.0f} N).")
    else:
        words = (f"No simple force term explains the discrepancy the recording implies (RMS {fit['rms_before']:.0f} N "
                 f"while moving); the missing physics is more likely in the air flow than in the forces.")
    return {"label": "empirical suggestion, not a declared effect", "quantity": "force discrepancy while moving [N]",
            "terms": fit["terms"], "words": words, "rms_before": fit["rms_before"], "rms_after": fit["rms_after"],
            "improvement": fit["improvement"], "samples": int(moving.sum())}


__all__ = ["empirical_term", "implied_force", "sparse_fit"]

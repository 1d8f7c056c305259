"""Candidates and units: the full grid, a seeded latin hypercube, Monte Carlo draws of tolerances.

Every draw comes from ``numpy.random.default_rng(seed)`` (or scipy's seeded ``qmc.LatinHypercube``)
in the parent process, before any task is sent, so a local and a Dask run of the same file
evaluate exactly the same candidates.
"""

from __future__ import annotations

import itertools

import numpy as np

from compliance.sweep.candidates.spec import Adjustable, Uncertain

__all__ = ["grid", "latin_hypercube", "to_normalised", "from_normalised", "draw_units"]


def _axis(a: Adjustable) -> tuple[float, ...]:
    if a.values is not None:
        return a.values
    return tuple(float(v) for v in np.linspace(a.low, a.high, a.steps))


def grid(adjust: tuple[Adjustable, ...]) -> list[dict]:
    """Every combination of the adjustable settings (``steps`` points per range)."""
    axes = [_axis(a) for a in adjust]
    return [{a.param.path: v for a, v in zip(adjust, combo)} for combo in itertools.product(*axes)]


def from_normalised(adjust: tuple[Adjustable, ...], u) -> dict:
    """Settings at normalised coordinates ``u`` in [0, 1] per parameter (lists: nearest allowed value)."""
    out = {}
    for a, x in zip(adjust, u):
        x = float(np.clip(x, 0.0, 1.0))
        if a.values is not None:
            k = min(int(x * len(a.values)), len(a.values) - 1)
            out[a.param.path] = a.values[k]
        else:
            out[a.param.path] = a.low + x * a.span
    return out


def to_normalised(adjust: tuple[Adjustable, ...], values: dict) -> np.ndarray:
    """Normalised coordinates of settings: (value - low) / (high - low); lists by index."""
    u = []
    for a in adjust:
        v = values[a.param.path]
        if a.values is not None:
            k = int(np.argmin([abs(v - w) for w in a.values]))
            u.append((k + 0.5) / len(a.values))
        else:
            u.append((v - a.low) / a.span)
    return np.asarray(u, float)


def latin_hypercube(adjust: tuple[Adjustable, ...], n: int, seed: int) -> list[dict]:
    """``n`` candidates from a seeded latin hypercube over the adjustable space."""
    from scipy.stats import qmc

    u = qmc.LatinHypercube(d=len(adjust), seed=np.random.default_rng(seed)).random(n)
    return [from_normalised(adjust, row) for row in u]


def draw_units(uncertain: tuple[Uncertain, ...], nominal: dict, n: int, seed: int) -> list[dict]:
    """``n`` manufactured units: each uncertain parameter drawn around its nominal SI value.

    A normal draw is clipped to the parameter's admissible bounds (a friction force cannot be
    negative); the clip is reported by the caller only through the drawn values themselves.
    """
    rng = np.random.default_rng(seed)
    cols = {}
    for u in uncertain:
        x0 = nominal[u.param.path]
        if u.distribution == "list":
            cols[u.param.path] = rng.choice(np.asarray(u.values), size=n)
            continue
        scale = u.spread * (abs(x0) if u.relative else 1.0)
        draw = rng.normal(0.0, 1.0, n) if u.distribution == "normal" else rng.uniform(-1.0, 1.0, n)
        cols[u.param.path] = np.clip(x0 + scale * draw, u.param.low, u.param.high)
    return [{k: float(v[i]) for k, v in cols.items()} for i in range(n)]

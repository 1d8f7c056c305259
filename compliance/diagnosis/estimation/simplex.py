"""Nelder-Mead simplex search whose evaluations may stop as soon as they cannot matter.

The search is the one of ``scipy.optimize.minimize(method="Nelder-Mead")`` (Nelder & Mead 1965;
scipy 1.17's standard coefficients rho = 1, chi = 2, psi = 1/2, sigma = 1/2, its order of
evaluations, its tie-breaking by ``numpy.argsort`` and its ``maxfev``, ``xatol`` and ``fatol``
stopping rules), step for step. Only one thing differs: each trial point is evaluated with the
*limit* above which its value no longer changes what the search does next:

- a reflected point that ends above the worst vertex is contracted inside whatever its value;
- an expanded point is kept only below the reflected point's value, an outside contraction
  only at or below it;
- an inside contraction is kept only below the worst vertex.

So ``f(u, limit)`` may return any number above ``limit`` once it knows the value exceeds it (a
replay stopped at the first segment where its residual already does: ``evidence.residuals.Bound``),
and the search visits the same points and returns the same result as with full evaluations.
Vertices of the simplex (the start, shrinks) are always evaluated in full.
"""

from __future__ import annotations

import math

import numpy as np

RHO, CHI, PSI, SIGMA = 1, 2, 0.5, 0.5


class _MaxFev(Exception):
    pass


def simplex_search(f, simplex: np.ndarray, maxfev: int, xatol: float, fatol: float) -> np.ndarray:
    """Vertex with the lowest value after the search from ``simplex`` ((k + 1, k) points).

    ``f(u, limit)`` returns the value at ``u``, or any number above ``limit`` when the value exceeds it.
    """
    calls = [0]

    def func(x, limit=math.inf):
        if calls[0] >= maxfev:
            raise _MaxFev
        calls[0] += 1
        return float(f(np.copy(x), limit))

    sim = np.atleast_2d(simplex).astype(float).copy()
    n = sim.shape[1]
    fsim = np.full((n + 1,), np.inf, dtype=float)
    try:
        for k in range(n + 1):
            fsim[k] = func(sim[k])
    except _MaxFev:
        pass
    ind = np.argsort(fsim)
    sim, fsim = np.take(sim, ind, 0), np.take(fsim, ind, 0)
    ind = np.argsort(fsim)
    fsim, sim = np.take(fsim, ind, 0), np.take(sim, ind, 0)
    while calls[0] < maxfev:
        try:
            if np.max(np.ravel(np.abs(sim[1:] - sim[0]))) <= xatol and np.max(np.abs(fsim[0] - fsim[1:])) <= fatol:
                break
            _iterate(func, sim, fsim, n)
        except _MaxFev:
            pass
        ind = np.argsort(fsim)
        sim, fsim = np.take(sim, ind, 0), np.take(fsim, ind, 0)
    return sim[0]


def _iterate(func, sim: np.ndarray, fsim: np.ndarray, n: int) -> None:
    """One Nelder-Mead step on the sorted simplex, in place."""
    xbar = np.add.reduce(sim[:-1], 0) / n
    xr = (1 + RHO) * xbar - RHO * sim[-1]
    fxr = func(xr, fsim[-1])  # above the worst vertex: an inside contraction, whatever the value
    if fxr < fsim[0]:
        xe = (1 + RHO * CHI) * xbar - RHO * CHI * sim[-1]
        fxe = func(xe, fxr)
        if fxe < fxr:
            sim[-1], fsim[-1] = xe, fxe
        else:
            sim[-1], fsim[-1] = xr, fxr
        return
    if fxr < fsim[-2]:
        sim[-1], fsim[-1] = xr, fxr
        return
    if fxr < fsim[-1]:
        xc = (1 + PSI * RHO) * xbar - PSI * RHO * sim[-1]
        fxc = func(xc, fxr)
        if fxc <= fxr:
            sim[-1], fsim[-1] = xc, fxc
            return
    else:
        xcc = (1 - PSI) * xbar + PSI * sim[-1]
        fxcc = func(xcc, fsim[-1])
        if fxcc < fsim[-1]:
            sim[-1], fsim[-1] = xcc, fxcc
            return
    for j in range(1, n + 1):  # shrink towards the best vertex: new vertices, evaluated in full
        sim[j] = sim[0] + SIGMA * (sim[j] - sim[0])
        fsim[j] = func(sim[j])


__all__ = ["simplex_search"]

"""Monte Carlo bands on a check's verdicts: a Latin hypercube over the plant file's declared ranges.

``govcheck check --uncertainty N`` draws N plants from a seeded Latin hypercube over every ranged
parameter (each uniform over its range, the same ranges the local bands use), judges each with the
sweep machinery (one campaign per candidate, no traces, linear requirements off), and replaces the
local band of every modelled verdict by the spread of the candidates' worst values. The deciding
parameters are ranked by the change of the value across each range estimated from a least-squares
fit of the candidates (a linear response surface). A plant file's ``[commissioning]`` settings are not made
again per plant here (the local bands make them at each range end): the band's method says so.
docs/requirements.md, "Uncertainty".
"""

from __future__ import annotations

import numpy as np

from compliance.campaign.uncertainty import apply_band, modelled_verdicts, ranged_parameters, top_assumptions
from compliance.sweep.candidates.evaluate import judged, make_context
from compliance.model.parameters import param_handle
from compliance.sweep.candidates.runner import run_candidates
from compliance.sweep.candidates.sampling import latin_hypercube
from compliance.sweep.candidates.spec import Adjustable

__all__ = ["monte_carlo_bands"]


def _swings(cands: list[dict], vals: list[float], ranged) -> dict:
    """Per parameter (change over the range, mirrored) from a least-squares linear fit of value on parameters."""
    keys = [k for k, _ in ranged]
    X = np.array([[c[k] for k in keys] for c in cands], float)
    y = np.asarray(vals, float)
    A = np.column_stack([np.ones(len(y)), X])
    coef = np.linalg.lstsq(A, y, rcond=None)[0][1:]
    out = {}
    for g, (k, rng) in zip(coef, ranged):
        half = 0.5 * g * (rng["high"] - rng["low"])
        out[k] = (half, -half)
    return out


def monte_carlo_bands(cfg, reqset, entries: list[dict], n: int, *, seed: int = 0, workers=None, progress=False) -> dict:
    """Replace the bands of the modelled verdicts by a Latin-hypercube Monte Carlo of ``n`` plants.

    Parameters
    ----------
    cfg : PlantConfig
    reqset : RequirementSet
    entries : list of dict
        A campaign's requirement entries (``campaign.judge``; updated in place).
    n : int
        Number of candidate plants (>= 2).
    seed : int
        Seed of the Latin hypercube (the same seed draws the same plants).

    Returns
    -------
    dict
        The ``uncertainty`` section: method, parameters, candidates judged and invalid, top assumptions.
    """
    ranged = ranged_parameters(cfg)
    paths = {k: param_handle(k, f"{cfg.path}: {k}.range") for k, _ in ranged}
    adjust = tuple(Adjustable(paths[k], rng["low"], rng["high"], None, 2) for k, rng in ranged)
    cands = latin_hypercube(adjust, n, seed)
    ctx = make_context(cfg, reqset, paths)
    rows, _ = run_candidates(ctx, cands, workers=workers, progress=progress, label="uncertainty")
    ok = [(c, r) for c, r in zip(cands, rows) if judged(r)]
    for e in modelled_verdicts(entries):
        got = [(c, r["requirements"][e["id"]]["value"]) for c, r in ok
               if r["requirements"].get(e["id"], {}).get("value") is not None]
        if len(got) < 2:
            continue
        vals = [v for _, v in got]
        lo, hi = min(vals + [e["worst"]["value"]]), max(vals + [e["worst"]["value"]])
        apply_band(e, lo, hi, _swings([c for c, _ in got], vals, ranged), f"monte carlo (latin hypercube, {len(got)} plants"
                   + (", settings as the file gives them, not commissioned per plant)" if cfg.commissioning else ")"))
    return {"method": "monte_carlo", "samples": n, "judged": len(ok), "invalid": n - len(ok), "seed": seed,
            "parameters": [{"parameter": k, **rng} for k, rng in ranged], "top_assumptions": top_assumptions(entries, cfg)}

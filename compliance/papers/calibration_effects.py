"""Effect search against the paper's figures: which declared effect, added, closes which figure.

After the unstated parameters are calibrated, some figures may still sit outside the paper's
scatter (the steady errors: an ideal dead zone leaves the 0.86 mm stall band). Each declared
effect of ``compliance.effects`` is switched on at the starting points of the diagnosis
(``diagnosis.candidates.effect_candidate``: a few physically spread values of its parameters),
on top of the calibrated configuration, and scored with the same objective. The result says,
per effect, the best cost and which figures it brings inside the scatter that were outside.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from compliance.diagnosis.servo.candidates import effect_candidate
from compliance.effects import EFFECTS
from compliance.model.config import PlantConfig
from compliance.papers.calibration import map_configs
from compliance.papers.calibration_objective import rows_of
from compliance.papers.plant_a import Row, scaled_miss

MAX_POINTS = 9  # grid points per effect (evenly thinned): enough to see whether it can move a figure
# starting points for an effect the diagnosis has no grid for yet (null leakage 0.1-1 % of full opening,
# pressure gain at null over 0.1-0.65 V)
FALLBACK_GRIDS = {
    "valve_null_flow": tuple({"null_opening": a, "null_width": w} for a in (0.001, 0.003, 0.01) for w in (0.1, 0.3, 0.65)),
}


@dataclass
class EffectResult:
    """What one effect does to the figures at its best grid point."""

    name: str
    cost: float
    params: dict
    closes: list[str] = field(default_factory=list)  # figures brought inside the scatter
    opens: list[str] = field(default_factory=list)  # figures pushed outside it
    rows: list[Row] = field(default_factory=list)
    points: list[tuple[float, dict]] = field(default_factory=list)  # every grid point tried, best first
    evaluations: int = 0


def _label(r: Row) -> str:
    return f"{r.test}: {r.metric}"


def _inside(r: Row) -> bool:
    m = scaled_miss(r)
    return m is not None and abs(m) <= 1.0


def _thin(grid: tuple[dict, ...]) -> list[dict]:
    if len(grid) <= MAX_POINTS:
        return list(grid)
    step = (len(grid) - 1) / (MAX_POINTS - 1)
    return [grid[round(i * step)] for i in range(MAX_POINTS)]


def effect_search(cfg: PlantConfig, conditions: dict, base_rows: list[Row], workers: int,
                  names: tuple[str, ...] | None = None) -> list[EffectResult]:
    """Score every declared effect (not already on) added to ``cfg``; best first.

    Parameters
    ----------
    cfg : PlantConfig
        The calibrated configuration without the effect.
    conditions : dict
        Test conditions of the calibration.
    base_rows : list of Row
        Figures of ``cfg`` (what an effect must improve on).
    workers : int
    names : tuple of str, optional
        Effects to try (default: every declared effect not already switched on).
    """
    names = names or tuple(n for n in EFFECTS if n not in cfg.effects)
    cfgs, owners = [], []
    for name in names:
        grid = effect_candidate(name).grid
        if grid == ({},) and name in FALLBACK_GRIDS:
            grid = FALLBACK_GRIDS[name]
        for point in _thin(grid):
            cfgs.append(cfg.replace(effects={name: point}))
            owners.append((name, dict(point)))
    costs = map_configs(cfgs, [conditions], workers)
    best: dict[str, tuple[float, int]] = {}
    tried: dict[str, list[tuple[float, dict]]] = {}
    for i, ((name, point), (c, *_)) in enumerate(zip(owners, costs)):
        tried.setdefault(name, []).append((c, point))
        if name not in best or c < best[name][0]:
            best[name] = (c, i)
    out = []
    for name, (c, i) in best.items():
        rows = rows_of(cfgs[i], conditions) or []
        res = EffectResult(name, c, dict(cfgs[i].effects[name]), rows=rows,
                           points=sorted(tried[name], key=lambda cp: cp[0]), evaluations=len(tried[name]))
        for b, a in zip(base_rows, rows):
            if not _inside(b) and _inside(a):
                res.closes.append(_label(a))
            elif _inside(b) and not _inside(a) and scaled_miss(b) is not None:
                res.opens.append(_label(a))
        out.append(res)
    return sorted(out, key=lambda r: r.cost)


def format_effect_search(results: list[EffectResult], base_cost: float) -> str:
    """Plain-text ranking of the effect search."""
    lines = [f"Effect search on the figures (calibrated plant, cost {base_cost:.1f} without any added effect)",
             f"  {'effect':28s} {'best cost':>9s}  figures brought inside the scatter (and pushed out)"]
    for r in results:
        moved = f"{len(r.closes)} in" + (f", {len(r.opens)} out" if r.opens else "")
        lines.append(f"  {r.name:28s} {r.cost:9.1f}  {moved}: " + ("; ".join(r.closes) or "none"))
        if r.opens:
            lines.append(f"  {'':28s} {'':9s}  out: " + "; ".join(r.opens))
    return "\n".join(lines)

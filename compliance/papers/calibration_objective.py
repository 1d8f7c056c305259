"""The metric-level objective of the calibration: the paper's figures, each in units of its scatter.

Every compared row of ``plant_a.figure_rows`` (settling times and steady errors of figs. 9-12,
stroke times and peak speed of section 5.2) contributes r^2, r = (simulated - paper) / scatter,
with the scatter of ``plant_a.TOLERANCES`` (settling 35 %, steady error 0.3 mm, stroke times
5 %, peak speed 30 %). r^2 <= 1 is inside the paper's own scatter. A figure the simulation
cannot measure (no settling) costs ``MISSING_COST``; a configuration the solver rejects costs
infinity. The objective is a sum of squares so that every figure keeps pulling towards the
paper, not only the ones outside their band.
"""

from __future__ import annotations

import math

from compliance.errors import InputError, SimulationError
from compliance.model.config import PlantConfig
from compliance.papers.plant_a import Row, case_test, figure_rows, scaled_miss

CAP = 10.0  # |r| beyond 10 scatters adds no more: one wild figure must not hide the others
# a figure that is not measured at all counts as the worst measured one: cheaper, and the search would learn to
# break a test (a full stroke that never reaches 75 %) rather than bring its figure closer
MISSING_COST = CAP**2


def rows_of(cfg: PlantConfig, conditions: dict, memo: dict | None = None,
            targets: dict | None = None, tests: frozenset | None = None) -> list[Row] | None:
    """The simulated figure rows, or None when the configuration does not simulate.

    ``targets``: (test, metric) -> value replacing the paper's figure (None drops the row), for
    calibrating to figures other than the paper's (e.g. figures the model itself generated).
    ``tests``: simulate only these tests (``StepCase.test`` names); with ``targets``, only the targets' tests.
    """
    if targets is not None and tests is None:
        tests = frozenset(case_test(t) for (t, _), v in targets.items() if v is not None)
    try:
        rows = [row for _, _, row in figure_rows(cfg, conditions, memo, tests)]
    except (SimulationError, InputError, FloatingPointError):
        return None
    if targets is not None:
        for r in rows:
            r.paper = targets.get((r.test, r.metric))
    return rows


def row_cost(row: Row) -> float:
    """r^2 of one row (0 for a row the paper gives no figure for)."""
    r = scaled_miss(row)
    if r is None:
        return 0.0
    if not math.isfinite(r):
        return MISSING_COST
    return min(abs(r), CAP) ** 2


def cost(rows: list[Row] | None) -> float:
    """Sum of r^2 over the compared rows (infinity when the run failed)."""
    if rows is None:
        return math.inf
    return float(sum(row_cost(r) for r in rows))


def within(rows: list[Row]) -> tuple[int, int]:
    """(rows inside the paper's scatter, rows compared)."""
    rs = [scaled_miss(r) for r in rows]
    rs = [r for r in rs if r is not None]
    return sum(1 for r in rs if abs(r) <= 1.0), len(rs)


def best_conditions(cfg: PlantConfig, condition_sets: list[dict],
                    targets: dict | None = None) -> tuple[float, int, tuple[float, ...]]:
    """(lowest cost, index of its condition set, cost under each set) of ``cfg`` (runs shared between sets)."""
    memo: dict = {}
    costs = tuple(cost(rows_of(cfg, cond, memo, targets)) for cond in condition_sets)
    i = min(range(len(costs)), key=lambda j: costs[j])
    return costs[i], i, costs

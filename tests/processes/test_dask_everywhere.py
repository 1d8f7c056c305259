"""The Dask option reaches every parallel stage through the one executor, with the local pool's results.

Each stage is run twice - on the local process pool and on a Dask cluster (in-process workers on
``inproc://``, addressed as ``--scheduler`` would be) - and must give the same numbers.
"""

from __future__ import annotations

import json
import pickle
from pathlib import Path

import pytest

from compliance.model.config import load_plant
from compliance.processes import PerProcess

FIXTURE = Path(__file__).resolve().parents[1] / "data" / "results_fixture.json"
BUILT: list = []


def _build(x):
    BUILT.append(x)
    return {"x": x}


def test_per_process_context_is_built_once_and_travels_as_its_recipe():
    BUILT.clear()
    ctx = PerProcess(_build, 3)
    assert ctx.get() is ctx.get() and BUILT == [3]  # built on first use, kept
    copy = pickle.loads(pickle.dumps(ctx))  # what a Dask worker receives: the recipe, not the built value
    assert copy._value is None and copy.get() == {"x": 3} and BUILT == [3, 3]


def test_report_figures_on_dask_equal_the_local_ones(dask_cluster):
    from compliance.report.render import build_report

    results = json.loads(FIXTURE.read_text())
    _, local = build_report(json.loads(json.dumps(results)), workers=2, appendix="none")
    _, remote = build_report(results, appendix="none", scheduler=dask_cluster.scheduler_address)
    assert len(local) >= 4 and remote == local  # from 4 figures on they are drawn in parallel


def test_calibration_points_on_dask_equal_the_local_ones(dask_cluster):
    from compliance.papers.calibration import calibrate
    from compliance.papers.calibration_table import UNSTATED
    from compliance.papers.plant_a import DEFAULT_CONDITIONS

    cfg = load_plant("plant-a")
    table = tuple(u for u in UNSTATED if u.path == "valve.saturation_voltage")
    kw = {"sobol_points": 4, "table": table, "conditions": DEFAULT_CONDITIONS, "profiles": False, "compass_iterations": 1,
          "starts": 1, "restarts": False, "workers": 2}
    local = calibrate(cfg, **kw)
    remote = calibrate(cfg, scheduler=dask_cluster.scheduler_address, **kw)
    assert local.evaluations == remote.evaluations >= 6  # start + 4 Sobol points + at least one compass move
    assert remote.values == local.values and remote.cost_after == local.cost_after


@pytest.mark.slow
def test_benchmark_cases_on_dask_equal_the_local_ones(dask_cluster):
    from compliance.diagnosis.scoring.benchmark import run_benchmark

    cfg = load_plant("plant-a")
    kw = {"effects": ["internal_leakage"], "library": ["internal_leakage"], "cases": 1, "seed": 4, "null": False,
          "miscalibrations": False}
    local = run_benchmark(cfg, jobs=1, **kw)
    seen = []
    remote = run_benchmark(cfg, scheduler=dask_cluster.scheduler_address, progress=seen.append, **kw)
    keys = ("kind", "truth", "predicted", "verdict", "correct", "true_params")
    assert [{k: c[k] for k in keys} for c in remote["cases"]] == [{k: c[k] for k in keys} for c in local["cases"]]
    assert len(seen) == len(remote["cases"]) == 1  # the caller hears of every case as it finishes

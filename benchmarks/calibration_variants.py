"""Calibration variants that say what stops `reproduce plant-a --calibrate` (docs/calibration.md, "What is left").

Each variant runs the calibration's search (``papers.calibration.calibrate``) from the published plant with
the valve's null flow on, seeded with the saved calibrated plant (32 Sobol points, 2 compass starts, no
profiles), over a different table of what may move:

- ``physical``: the unstated parameters within physical limits (``calibration_reach.PHYSICAL``) instead of
  their plausible ranges: whether the ranges are what stops the fit;
- ``kp``: the plausible ranges plus the printed K_P (100-2000 V/m): what the reach search's K_P
  variants suggest, as a fit of all figures together.

Usage: python benchmarks/calibration_variants.py [physical] [kp]   (about 60-80 s CPU each)
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # runnable as documented from a checkout

from compliance.model.config import load_plant  # noqa: E402
from compliance.papers.calibration import calibrate
from compliance.papers.calibration_objective import within
from compliance.papers.calibration_reach import PHYSICAL, PRINTED
from compliance.papers.calibration_run import _cpu_seconds
from compliance.papers.calibration_table import EFFECT_UNSTATED, UNSTATED

TABLES = {
    "physical": PHYSICAL,
    "kp": UNSTATED + EFFECT_UNSTATED + tuple(u for u in PRINTED if u.path == "controller.kp"),
}


def main(names: list[str]) -> None:
    saved = load_plant("models/plant-a-calibrated.toml")
    start = load_plant("plant-a").replace(effects={"valve_null_flow": {}})
    for name in names or list(TABLES):
        t0, c0 = time.perf_counter(), _cpu_seconds()
        cal = calibrate(start, table=TABLES[name], seeds=(saved,), sobol_points=32, starts=2, profiles=False)
        k, n = within(cal.rows_after)
        print(f"{name}: cost {cal.cost_after:.2f}, {k} of {n} inside, conditions {cal.conditions}; "
              f"{time.perf_counter() - t0:.0f} s wall, {_cpu_seconds() - c0:.0f} s CPU")
        print("  " + ", ".join(f"{key} = {v:.4g}" for key, v in cal.values.items()))
        print("  figures: " + " ".join(f"{(r.simulated or float('nan')) * (1e3 if r.unit == 'mm' else 1):.3g}"
                                       for r in cal.rows_after if r.paper is not None))


if __name__ == "__main__":
    main(sys.argv[1:])

"""Benchmark: the full plant-A campaign against shpp-400kw.toml (budget: <= 15 s wall on 2 cores).

Usage::

    .venv/bin/python benchmarks/campaign.py [--workers 2] [--repeat 3] [--serial] [--budget 15]

Prints the figures as a Markdown table for docs/performance.md and exits 1 when the median
wall time of the parallel campaign exceeds the budget. The numba core is compiled (or loaded
from its cache) once before timing, and that time is reported on its own line: a cold cache
is a one-off cost of the first run after installation or after the core changes.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plant", default=str(ROOT / "models" / "plant-a.toml"))
    ap.add_argument("--requirements", default=str(ROOT / "requirements" / "shpp-400kw.toml"))
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--serial", action="store_true", help="also time the serial campaign (workers = 1)")
    ap.add_argument("--budget", type=float, default=15.0, help="wall-time budget of the parallel campaign [s]")
    args = ap.parse_args(argv)

    t0 = time.perf_counter()
    from compliance.model.config import load_plant
    from compliance.campaign.executor import warm_up
    from compliance.processes import available_cores
    from compliance.campaign.run import run_campaign
    from compliance.requirements.loading import load_requirements

    cfg = load_plant(args.plant)
    reqset = load_requirements(args.requirements)
    t_import = time.perf_counter() - t0
    t0 = time.perf_counter()
    warm_up(cfg)
    t_compile = time.perf_counter() - t0

    def timed(workers):
        walls = []
        res = None
        for _ in range(args.repeat):
            t = time.perf_counter()
            res = run_campaign(cfg, reqset, workers=workers, progress=False)
            walls.append(time.perf_counter() - t)
        return walls, res

    walls, res = timed(args.workers)
    rows = [("import + load plant and requirements", f"{t_import:.2f} s"),
            ("numba core compile / cache load (once)", f"{t_compile:.2f} s"),
            (f"campaign, {res['timing']['workers']} workers (median of {args.repeat})", f"{statistics.median(walls):.2f} s"),
            ("campaign, min / max", f"{min(walls):.2f} / {max(walls):.2f} s"),
            ("runs (procedure x operating point)", str(res["timing"]["runs"])),
            ("sum of run wall times (CPU work)", f"{res['timing']['run_wall_sum']:.2f} s")]
    if args.serial:
        sw, _ = timed(1)
        rows.append((f"campaign, serial (median of {args.repeat})", f"{statistics.median(sw):.2f} s"))
    print(f"# govcheck campaign benchmark: {Path(args.plant).name} vs {Path(args.requirements).name}")
    print(f"machine: {platform.processor() or platform.machine()}, {available_cores()} cores available "
          f"(os.cpu_count {os.cpu_count()}), Python {platform.python_version()}, verdict {res['summary']['status']}")
    print()
    print("| quantity | value |")
    print("|---|---|")
    for k, v in rows:
        print(f"| {k} | {v} |")
    med = statistics.median(walls)
    ok = med <= args.budget
    print()
    print(f"budget {args.budget:g} s: {'met' if ok else 'EXCEEDED'} (median {med:.2f} s)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())

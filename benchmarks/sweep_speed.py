"""Benchmark: sweep throughput (simulated 3 s step tests per minute), Dask LocalCluster vs the local pool.

Usage::

    .venv/bin/python benchmarks/sweep_speed.py [--candidates 40] [--workers 2] [--rounds 3] [--no-dask]

Plant A against shpp-400kw.toml (every nonlinear procedure x operating point, the linear-model
requirement off as in a sweep), candidates from the latin hypercube of
models/sweeps/plant-a-remedies.toml. Prints, all measured in this run:

- the plain reference: one candidate judged by the stock campaign (``run_campaign``, serial,
  plot traces and linear requirement on) against the sweep's evaluation (no traces, no linear),
  CPU seconds each, and the ratio;
- simulated plant seconds per candidate (every simulation's duration, counted) and the
  throughput in simulated 3 s step tests per minute on the local pool;
- the same candidates on a Dask ``LocalCluster`` of ``--workers`` processes (loopback), its wall
  time / the local pool's (target <= 1.3), and whether the results are identical;
- the extrapolated wall time of a 1000-candidate sweep and a 2000-unit yield run (a unit costs
  one candidate's campaign), from the measured local throughput.

The machine is shared: the load average is printed before and after; ratios measured in the
same run are the robust figures.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def _simulated_seconds(ctx) -> float:
    """Plant seconds simulated by one candidate's campaign (every simulate() call counted)."""
    import compliance.simulation as sim
    from compliance.sweep.candidates.evaluate import evaluate_one

    real, total = sim.simulate, [0.0]

    def counting(cfg, scenario):
        total[0] += scenario.duration
        return real(cfg, scenario)

    sim.simulate = counting
    try:
        evaluate_one(ctx, {})
    finally:
        sim.simulate = real
    return total[0]


def _cpu(fn) -> float:
    t = time.process_time()
    fn()
    return time.process_time() - t


def _dask_client(workers):
    from distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                           dashboard_address="127.0.0.1:0")
    return Client(cluster), cluster


def _timed(fn):
    t = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--candidates", type=int, default=40)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--no-dask", action="store_true")
    ap.add_argument("--rounds", type=int, default=3, help="alternating local / Dask rounds (medians are reported)")
    args = ap.parse_args(argv)
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs")

    from compliance.campaign.executor import warm_up
    from compliance.campaign.run import run_campaign
    from compliance.sweep.candidates.evaluate import evaluate_one, make_context
    from compliance.sweep.run import load_inputs
    from compliance.sweep.candidates.runner import run_candidates
    from compliance.sweep.candidates.sampling import latin_hypercube
    from compliance.sweep.candidates.spec import load_sweep

    spec = load_sweep(ROOT / "models" / "sweeps" / "plant-a-remedies.toml")
    cfg, reqset = load_inputs(spec)
    ctx = make_context(cfg, reqset, spec.paths)
    warm_up(cfg)
    evaluate_one(ctx, {})
    stock = _cpu(lambda: run_campaign(cfg, reqset, workers=1, progress=False))
    lean = _cpu(lambda: evaluate_one(ctx, {}))
    sim_s = _simulated_seconds(ctx)
    print(f"one candidate, CPU: stock campaign {stock:.2f} s, sweep evaluation {lean:.2f} s "
          f"-> {stock / lean:.1f}x less; {sim_s:.0f} s of plant time simulated ({sim_s / 3:.0f} x 3 s step tests)")

    idle = 2 * 60 / lean
    print(f"projection from CPU time (2 idle cores, no pool overhead): {idle:.0f} candidates/min = "
          f"{idle * sim_s / 3:.0f} step tests/min; 1000 candidates {1000 / idle:.1f} min")

    cands = latin_hypercube(spec.adjust, args.candidates, spec.seed)
    client = cluster = None
    if not args.no_dask:
        t = time.perf_counter()
        client, cluster = _dask_client(args.workers)
        run_candidates(ctx, cands[:args.workers], client=client, progress=False)  # workers load the numba cache
        print(f"dask LocalCluster x {args.workers}: start-up and worker warm-up {time.perf_counter() - t:.1f} s")
    walls, ratios = [], []
    try:
        for r in range(args.rounds):  # local and Dask alternate, so a change of the machine's load hits both
            (local, stats), wall = _timed(lambda: run_candidates(ctx, cands, workers=args.workers, progress=False))
            walls.append(wall)
            line = f"round {r + 1}: local pool x {stats.workers} {wall:.1f} s"
            if client is not None:
                (remote, _), dwall = _timed(lambda: run_candidates(ctx, cands, client=client, progress=False))
                ratios.append(dwall / wall)
                line += f", dask {dwall:.1f} s -> dask / local = {dwall / wall:.2f}; identical: {remote == local}"
            print(line)
    finally:
        if client is not None:
            client.close()
            cluster.close()
    wall = sorted(walls)[len(walls) // 2]
    per_min = 60 * len(cands) / wall
    print(f"local pool, median of {len(walls)}: {len(cands)} candidates in {wall:.1f} s = {per_min:.0f} candidates/min "
          f"= {per_min * sim_s / 3:.0f} simulated 3 s step tests per minute (target >= 20000)")
    print(f"extrapolated from that wall time: 1000-candidate sweep {1000 / per_min:.1f} min, 2000-unit yield "
          f"{2000 / per_min:.1f} min (target < 15 min each)")
    if ratios:
        print(f"dask / local, median of {len(ratios)} rounds: {sorted(ratios)[len(ratios) // 2]:.2f} (target <= 1.3)")
    print(f"load average after: {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

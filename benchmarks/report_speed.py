"""Time the full plant-A report (HTML + PDF) from saved results.

    .venv/bin/python benchmarks/report_speed.py                    # simulates plant-a x shpp-400kw first
    .venv/bin/python benchmarks/report_speed.py --results r.json   # render saved results only
    .venv/bin/python benchmarks/report_speed.py --results r.json --linear lin.json --repeat 3

Prints the wall time of figure drawing, HTML and PDF, their sum (the budget is 20 s on 2 cores)
and the CPU time of the main process. The simulation is not timed.
"""

from __future__ import annotations

import argparse
import json
import resource
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from compliance.report import render as R  # noqa: E402

BUDGET = 20.0  # [s] issue 8: full plant-A report, HTML + PDF, 2 cores


def _results(args) -> dict:
    if args.results:
        return json.loads(Path(args.results).read_text(encoding="utf-8"))
    from compliance.model.config import load_plant
    from compliance.campaign.run import run_campaign
    from compliance.requirements.loading import load_requirements

    return json.loads(json.dumps(run_campaign(load_plant("plant-a"), load_requirements("shpp-400kw"), progress=False),
                                 default=float))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--results", help="results JSON of govcheck check (default: simulate plant-a x shpp-400kw)")
    ap.add_argument("--linear", help="linear analysis JSON to include (govcheck linear --json)")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=None, help="figure workers (default: available cores)")
    args = ap.parse_args()
    res = _results(args)
    if args.linear:
        res["linear"] = json.loads(Path(args.linear).read_text(encoding="utf-8"))
    n_fig = sum(len(r.get("traces") or []) for r in res.get("runs") or [])
    totals = []
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(args.repeat):
            c0, t0 = time.process_time(), time.perf_counter()
            k0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            ctx, svgs = R.build_report(res, args.jobs)
            t1 = time.perf_counter()
            timing = R._emit("report.html.j2", ctx, svgs, Path(tmp) / "r.html", Path(tmp) / "r.pdf")
            t2 = time.perf_counter()
            totals.append(t2 - t0)
            size = (Path(tmp) / "r.pdf").stat().st_size
            k1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            child = (k1.ru_utime + k1.ru_stime) - (k0.ru_utime + k0.ru_stime)
            print(f"run {k + 1}: figures {t1 - t0:.2f} s ({len(svgs)} figures, {n_fig} run traces), html {timing['html']:.2f} s, "
                  f"pdf {timing['pdf']:.2f} s, total {t2 - t0:.2f} s; CPU main {time.process_time() - c0:.2f} s + figure workers "
                  f"{child:.2f} s; "
                  f"pdf {size / 1e6:.2f} MB")
    best = min(totals)
    print(f"report render time: {best:.2f} s (best of {len(totals)}, median {statistics.median(totals):.2f} s); "
          f"budget {BUDGET:.0f} s: {'OK' if best <= BUDGET else 'OVER'}")
    return 0 if best <= BUDGET else 1


if __name__ == "__main__":
    sys.exit(main())

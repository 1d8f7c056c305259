"""Time the README's main command in one process, phase by phase: campaign (with the bands), model evidence,
linear analysis (with the stability margins), report.

    python benchmarks/main_command.py [--repeat 3] [--appendix summary]

Prints, per repeat, the wall and CPU time (this process and its workers) of each phase and of
the whole, with the load average; then the minimum wall times. The command itself is
``govcheck check models/plant-a.toml -r requirements/shpp-400kw.toml --linear --report R.html --pdf R.pdf``;
run it after one warm-up (numba cache filled). On a shared machine the CPU time is the steadier
figure: on 2 idle cores the wall time approaches the critical path (about CPU / 2 for the
parallel parts).
"""

from __future__ import annotations

import argparse
import os
import resource
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # runnable as documented from a checkout, installed or not


def _cpu() -> float:
    a, b = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return a.ru_utime + a.ru_stime + b.ru_utime + b.ru_stime


def once(appendix: str, out: Path) -> dict:
    """One check as the command runs it: ``compliance.check`` (its stages timed by ``on_stage``), then the report."""
    from compliance.pipeline.chain import Check
    from compliance.report.render import render_report

    phases = {}
    t0, c0 = time.perf_counter(), _cpu()
    prepared = Check.of(ROOT / "models" / "plant-a.toml", ROOT / "requirements" / "shpp-400kw.toml", linear=True)
    mark = [time.perf_counter(), _cpu()]

    def on_stage(name):
        phases[name] = (time.perf_counter() - mark[0], _cpu() - mark[1])
        mark[:] = [time.perf_counter(), _cpu()]

    res = prepared.run(on_stage=on_stage)
    t, c = time.perf_counter(), _cpu()
    render_report(res, out / "r.html", out / "r.pdf", appendix=appendix)
    phases["report"] = (time.perf_counter() - t, _cpu() - c)
    phases["total"] = (time.perf_counter() - t0, _cpu() - c0)
    return phases


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--appendix", default="summary", choices=("none", "summary", "full"))
    args = ap.parse_args()
    best: dict = {}
    with tempfile.TemporaryDirectory() as d:
        for i in range(args.repeat):
            ph = once(args.appendix, Path(d))
            print(f"run {i + 1} (load {os.getloadavg()[0]:.1f}): "
                  + " | ".join(f"{k} {w:.1f} s wall, {c:.1f} s CPU" for k, (w, c) in ph.items()))
            for k, (w, c) in ph.items():
                best[k] = min(best.get(k, (w, c)), (w, c))
    print("min: " + " | ".join(f"{k} {w:.1f} s wall, {c:.1f} s CPU" for k, (w, c) in best.items()))


if __name__ == "__main__":
    main()

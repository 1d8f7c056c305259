"""Time the README's main command in one process, phase by phase: campaign (with its bands), model evidence, linear analysis, report.

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
    from compliance.campaign.run import run_campaign
    from compliance.linear.operating_points import linear_for_campaign
    from compliance.linear.stability import stability_margins
    from compliance.model_evidence import model_evidence
    from compliance.model.config import load_plant
    from compliance.report.render import render_report
    from compliance.requirements.loading import load_requirements

    phases = {}
    t0, c0 = time.perf_counter(), _cpu()
    cfg = load_plant(ROOT / "models" / "plant-a.toml")
    rs = load_requirements(ROOT / "requirements" / "shpp-400kw.toml")
    for name, job in (("campaign", lambda: run_campaign(cfg, rs, progress=False, uncertainty="local")),):
        t, c = time.perf_counter(), _cpu()
        res = job()
        phases[name] = (time.perf_counter() - t, _cpu() - c)
    t, c = time.perf_counter(), _cpu()
    res["model_evidence"] = model_evidence(cfg, res)  # the paper's measured figures beside the model's
    phases["evidence"] = (time.perf_counter() - t, _cpu() - c)
    t, c = time.perf_counter(), _cpu()
    res["linear"] = linear_for_campaign(cfg, rs)
    res["stability"] = stability_margins(cfg, rs, analyses=res["linear"]["analyses"])  # reused, as check does
    phases["linear"] = (time.perf_counter() - t, _cpu() - c)
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

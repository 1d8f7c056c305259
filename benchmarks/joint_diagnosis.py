"""Joint diagnosis of two recordings: does it settle what one recording leaves open, and how fast?

The --suggest-test case of docs/diagnosis.md: plant A with pressure-dependent seal friction
(k = 1.5e-6 /Pa), recorded by the project's simulator with the practice sensors (seeded) at the
full supply pressure (R1) and at 70 % of it (R2, the test the diagnosis proposes). Each recording
is diagnosed alone and both jointly, as cold processes
(``python -m compliance diagnose plant-a R1 [R2] --json OUT --jobs N``); the table gives the
verdict, the two rival explanations' chi2/N (friction level recalibrated, ``base``, against
``pressure_dependent_friction``), wall time, CPU time of the process and its workers, and the load.

A site case (``--site DIR``): every recording of a site-acceptance folder (the commissioning tests of one
servo: step series, open-loop full strokes, holds whose positioner goes to manual with the valve at null,
a dead-band staircase, a sinusoid; docs/acceptance.md) diagnosed jointly as one cold process, with its
wall time against the 2 min budget (15 recordings on 2 cores), CPU time, simulations, verdict and the
leading candidates; with the folder's truth when an ``ANSWERS.json`` beside it names the site's effects.

Run: .venv/bin/python benchmarks/joint_diagnosis.py [--jobs 2] [--profile practice|steps] [--effects a,b]
     .venv/bin/python benchmarks/joint_diagnosis.py --site /work/shared/practice-acceptance/site-p2 [--jobs 2]
(default: the 30 s practice profile and the full effect library). Not part of the test suite.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
K_TRUE = 1.5e-6  # 1/Pa
SUPPLY_FACTOR = 0.7
SITE_BUDGET = 120.0  # s for a 15-recording site on 2 cores (issue 35)


def _recordings(tmp: Path, profile: str) -> list[Path]:
    from compliance.model.config import load_plant
    from compliance.recordings.synth import PRACTICE_NOISE, synthesise, write_recording

    cfg = load_plant("plant-a")
    truth = cfg.replace(effects={"pressure_dependent_friction": {"coefficient": K_TRUE}})
    ps = cfg.p("air.supply_pressure")
    out = []
    for i, factor in enumerate((1.0, SUPPLY_FACTOR)):
        run = truth.replace(params={"air.supply_pressure": factor * ps})
        frame, meta = synthesise(run, profile, x0=0.06, load=7000.0, noise=PRACTICE_NOISE, seed=21 + i,
                                 duration=30.0 if profile == "practice" else 17.0)
        path, _ = write_recording(frame, meta, tmp / f"R{i + 1}_supply{int(round(factor * 100))}.csv.gz")
        out.append(path)
    return out


def _run(paths: list[Path], out: Path, jobs: int, effects: str | None) -> dict:
    cmd = [sys.executable, "-m", "compliance", "diagnose", "plant-a", *map(str, paths), "--json", str(out),
           "--jobs", str(jobs), "-q"] + (["--effects", effects] if effects else [])
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, cwd=ROOT, env={**os.environ, "PYTHONPATH": str(ROOT)}, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    d = json.loads(out.read_text())
    chi = {e["name"]: e["chi2_per_residual"] for e in d["effects"]}
    return {"wall": wall, "cpu": (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime),
            "verdict": d["verdict"], "winner": d.get("winner"), "ambiguous": d.get("ambiguous") or [],
            "base": chi.get("base"), "pdf": chi.get("pressure_dependent_friction"),
            "simulations": d["timing"]["simulations"]}


def _site(site: Path, jobs: int, effects: str | None) -> int:
    """The site case: every recording of ``site`` diagnosed jointly (one cold process)."""
    recs = sorted(site.glob("*.csv.gz")) + sorted(site.glob("*.csv"))
    if not recs:
        raise SystemExit(f"--site {site}: no recordings (*.csv, *.csv.gz)")
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "site.json"
        print(f"load before: {os.getloadavg()[0]:.1f}; site {site.name}: {len(recs)} recordings; jobs {jobs}")
        r = _run(recs, out, jobs, effects)
        d = json.loads(out.read_text())
    truth = None
    answers = site.parent / "ANSWERS.json"
    if answers.is_file():
        truth = (json.loads(answers.read_text()).get("sites") or {}).get(site.name, {}).get("effects")
    print(f"verdict: {r['verdict']} ({r['winner'] or '-'})" + (f"; truth: {', '.join(truth) or 'none'}" if truth is not None else ""))
    print(f"{'candidate':40s} {'k':>2s} {'chi2/N':>9s} {'dBIC':>10s}  parameters")
    for e in d["effects"][:6]:
        params = ", ".join(f"{p['name'].split('.')[-1]}={p['value']:.3g}" for p in e["parameters"])
        print(f"{e['name']:40s} {e['k']:2d} {e['chi2_per_residual']:9.3f} {e['delta_bic']:10.1f}  {params}")
    print(f"wall {r['wall']:.1f} s (budget {SITE_BUDGET:.0f} s: {'within' if r['wall'] <= SITE_BUDGET else 'OVER'}), "
          f"CPU {r['cpu']:.1f} s, {r['simulations']} simulations; load after: {os.getloadavg()[0]:.1f}")
    return 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--profile", choices=("practice", "steps"), default="practice")
    ap.add_argument("--effects", default=None, help="candidate effects (default: the full library)")
    ap.add_argument("--site", type=Path, default=None, help="a site-acceptance folder: every recording in it, jointly")
    args = ap.parse_args()
    if args.site is not None:
        return _site(args.site, args.jobs, args.effects)
    with tempfile.TemporaryDirectory() as tmp:
        r1, r2 = _recordings(Path(tmp), args.profile)
        print(f"load before: {os.getloadavg()[0]:.1f}; profile {args.profile}; jobs {args.jobs}")
        print(f"{'diagnosis':12s} {'verdict':26s} {'base chi2/N':>12s} {'pdf chi2/N':>11s} {'wall [s]':>9s} {'CPU [s]':>8s} {'sims':>5s}")
        for label, paths in (("R1 alone", [r1]), ("R2 alone", [r2]), ("R1+R2 joint", [r1, r2])):
            r = _run(paths, Path(tmp) / "out.json", args.jobs, args.effects)
            v = r["verdict"] + (" (pdf)" if r["winner"] == "pressure_dependent_friction" and r["verdict"] != "ambiguous" else "")
            print(f"{label:12s} {v:26s} {r['base'] or float('nan'):12.2f} {r['pdf'] or float('nan'):11.2f} "
                  f"{r['wall']:9.1f} {r['cpu']:8.1f} {r['simulations']:5d}")
        print(f"load after: {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

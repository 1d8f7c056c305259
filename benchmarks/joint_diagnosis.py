"""Joint diagnosis of two recordings: does it settle what one recording leaves open, and how fast?

The --suggest-test case of docs/diagnosis.md: plant A with pressure-dependent seal friction
(k = 1.5e-6 /Pa), recorded by the project's simulator with the practice sensors (seeded) at the
full supply pressure (R1) and at 70 % of it (R2, the test the diagnosis proposes). Each recording
is diagnosed alone and both jointly, as cold processes
(``python -m compliance diagnose plant-a R1 [R2] --json OUT --jobs N``); the table gives the
verdict, the two rival explanations' chi2/N (friction level recalibrated, ``base``, against
``pressure_dependent_friction``), wall time, CPU time of the process and its workers, and the load.

Run: .venv/bin/python benchmarks/joint_diagnosis.py [--jobs 2] [--profile practice|steps] [--effects a,b]
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


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--profile", choices=("practice", "steps"), default="practice")
    ap.add_argument("--effects", default=None, help="candidate effects (default: the full library)")
    args = ap.parse_args()
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

"""Diagnosis speed: wall time of ``govcheck diagnose`` on 30 s, 1 kHz recordings with the full library.

Budget (issue 6): <= 60 s per 30 s recording on 2 cores with the full effect library.
Measured as a cold process (``python -m compliance diagnose REC --plant plant-a --json OUT
--jobs N``: imports, numba cache load, reading, replays, every candidate fit, JSON) on the
four practice recordings when ``../shared`` is beside the repository (else on two synthetic
practice recordings), and the number of simulations each diagnosis ran.

Run: .venv/bin/python benchmarks/diagnose_speed.py [--jobs 2]
Not part of the timed test suite. The machine's other load counts: run it on a quiet machine.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
BUDGET = 60.0  # s per 30 s recording on 2 cores


def _recordings(tmp: Path) -> list[Path]:
    practice = ROOT.parent / "shared" / "practice-recordings"
    found = sorted(practice.glob("practice_*.csv.gz")) if practice.is_dir() else []
    if found:
        return found
    from compliance.model.config import load_plant
    from compliance.recordings.synth import synthesise, write_recording

    cfg = load_plant("plant-a")
    out = []
    for name, effects in (("synthetic_null", None), ("synthetic_heat", {"heat_transfer": {"conductance": 12.0}})):
        c = cfg.replace(effects=effects) if effects else cfg
        rec, meta = synthesise(c, x0=0.08, load=8000.0, kd=20.0, seed=1)
        path = tmp / f"{name}.csv.gz"
        write_recording(rec, meta, path)
        out.append(path)
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        rows = []
        for rec in _recordings(tmp):
            out = tmp / "diag.json"
            if out.exists():
                out.unlink()
            cmd = [sys.executable, "-m", "compliance", "diagnose", str(rec), "--plant", "plant-a", "--json", str(out),
                   "--jobs", str(args.jobs), "--quiet"]
            t0 = time.perf_counter()
            p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, check=False)
            wall = time.perf_counter() - t0
            if p.returncode != 0:
                raise SystemExit(f"diagnose failed ({p.returncode}) on {rec}: {p.stderr}")
            data = json.loads(out.read_text())
            rows.append((rec.name, wall, data["timing"]["seconds"], data["timing"]["simulations"], data["verdict"], data["winner"]))
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"govcheck diagnose, full library, --jobs {args.jobs} (load average at the end {load:.1f}):")
    print(f"{'recording':34s} {'wall [s]':>9s} {'in-process [s]':>15s} {'simulations':>12s}  verdict")
    for name, wall, inner, sims, verdict, winner in rows:
        print(f"{name:34s} {wall:9.1f} {inner:15.1f} {sims:12d}  {verdict} {winner or ''}")
    worst = max(r[1] for r in rows)
    print(f"worst {worst:.1f} s against the {BUDGET:.0f} s budget: {'within' if worst <= BUDGET else 'OVER'}")


if __name__ == "__main__":
    main()

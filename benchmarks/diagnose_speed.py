"""Diagnosis speed: wall time of ``govcheck diagnose`` on 30 s, 1 kHz recordings with the full library.

Budget (issue 24): <= 15 s per 30 s recording on 2 cores with the full effect library.
Measured as a cold process (``python -m compliance diagnose REC --json OUT --jobs N``: imports,
numba cache load, reading, replays, every candidate fit, JSON) on the four practice recordings
when ``../shared`` is beside the repository (else on two synthetic practice recordings), or on every
recording of ``--practice DIR`` (field logs of other lengths: the time is also given per 30 s of
recording), and the number of simulations each diagnosis ran.

The previous implementation is measured in the same run, on the same recordings, one after the
other: ``--against REV`` (default ``main``) is checked out in a temporary git worktree and run
the same way, and the ratio of the wall times is printed (``--against none`` skips it). Each
side's numba cache is warmed by one untimed diagnosis first, so compilation is not counted.

Run: .venv/bin/python benchmarks/diagnose_speed.py [--jobs 2] [--against main] [--recordings N] [--practice DIR]
Not part of the timed test suite. The machine's other load counts: run it on a quiet machine.
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
# the environment as the user's shell gave it, before this script imports compliance (which sets its own
# process-wide defaults, e.g. one BLAS thread): each side's process starts from it and sets its own
ENV = dict(os.environ)
BUDGET = 15.0  # s per 30 s recording on 2 cores (issue 24)


def _recordings(tmp: Path, practice: Path | None) -> list[Path]:
    if practice is not None:
        found = sorted(practice.glob("*.csv.gz")) + sorted(practice.glob("*.csv"))
        if not found:
            raise SystemExit(f"--practice {practice}: no recordings (*.csv, *.csv.gz)")
        return found
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


def _diagnose(code: Path, rec: Path, out: Path, jobs: int) -> tuple[float, dict, float]:
    """Wall time of one cold ``diagnose`` process running the package in ``code``, its JSON, and the CPU time of
    the process and its workers [s] (on a shared machine the wall time follows the others' load; the CPU time
    much less)."""
    if out.exists():
        out.unlink()
    env = dict(ENV, PYTHONPATH=str(code))
    env.pop("NUMBA_CACHE_DIR", None)  # each side its own cache, keyed by its own compiled sources
    cmd = [sys.executable, "-m", "compliance", "diagnose", str(rec), "--json", str(out), "--jobs", str(jobs), "--quiet"]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, cwd=code, capture_output=True, text=True, check=False, env=env)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        raise SystemExit(f"diagnose failed ({p.returncode}) in {code} on {rec}: {p.stderr[-2000:]}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, json.loads(out.read_text()), cpu


def _duration(rec: Path) -> float:
    """Length of the recording [s] (its time column)."""
    from compliance.recordings.reader import read_recording

    t = read_recording(str(rec))[0]["time"].to_numpy()
    return float(t[-1] - t[0])


def _per30(wall: float, row: dict) -> float:
    """Wall time per 30 s of recording [s]: the budget is per 30 s recording; a shorter log is not scaled up."""
    return wall * 30.0 / max(row["seconds"], 30.0)


def _previous(rev: str, tmp: Path) -> Path:
    """A temporary worktree of ``rev`` (the previous implementation)."""
    where = tmp / "previous"
    subprocess.run(["git", "worktree", "add", "--detach", str(where), rev], cwd=ROOT, check=True, capture_output=True)
    return where


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--against", default="main", help="git revision of the previous implementation, or 'none'")
    ap.add_argument("--recordings", type=int, default=0, help="only the first N recordings (0: all)")
    ap.add_argument("--practice", type=Path, default=None, help="time every recording of this folder instead")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        recs = _recordings(tmp, args.practice)[: args.recordings or None]
        sides = {"this": ROOT}
        if args.against != "none":
            sides["previous"] = _previous(args.against, tmp)
        try:
            rows = []
            for name, code in sides.items():
                _diagnose(code, recs[0], tmp / "warm.json", args.jobs)  # numba cache of this side, untimed
            for rec in recs:
                row = {"name": rec.name, "seconds": _duration(rec)}
                for name, code in sides.items():
                    wall, data, cpu = _diagnose(code, rec, tmp / f"{name}.json", args.jobs)
                    row[name] = (wall, data["timing"]["simulations"], data["verdict"], data["winner"], cpu)
                rows.append(row)
        finally:
            if "previous" in sides:
                subprocess.run(["git", "worktree", "remove", "--force", str(sides["previous"])], cwd=ROOT, check=False)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"govcheck diagnose, full library, --jobs {args.jobs} (load average at the end {load:.1f}):")
    print(f"{'recording':52s} {'length [s]':>10s} {'wall [s]':>9s} {'per 30 s':>9s} {'CPU [s]':>8s} {'simulations':>12s} "
          f"{'previous [s]':>13s} {'CPU [s]':>8s} {'sims':>5s} {'ratio':>6s}  verdict")
    for r in rows:
        wall, sims, verdict, winner, cpu = r["this"]
        prev = r.get("previous")
        extra = f"{prev[0]:13.1f} {prev[4]:8.1f} {prev[1]:5d} {prev[0] / wall:6.2f}" if prev else f"{'-':>13s} {'-':>8s} {'-':>5s} {'-':>6s}"
        same = "" if not prev or (prev[2], prev[3]) == (verdict, winner) else f"  (previous: {prev[2]} {prev[3] or ''})"
        print(f"{r['name']:52s} {r['seconds']:10.1f} {wall:9.1f} {_per30(wall, r):9.1f} {cpu:8.1f} {sims:12d} {extra}  "
              f"{verdict} {winner or ''}{same}")
    worst = max(_per30(r["this"][0], r) for r in rows)
    if "previous" in rows[0]:
        total = sum(r["previous"][0] for r in rows) / sum(r["this"][0] for r in rows)
        cpu = sum(r["previous"][4] for r in rows) / sum(r["this"][4] for r in rows)
        sims = sum(r["previous"][1] for r in rows) / sum(r["this"][1] for r in rows)
        print(f"speed ratio against {args.against} (previous wall / this wall, same run): {total:.2f}; "
              f"CPU time ratio {cpu:.2f}; simulations ratio {sims:.2f}")
    print(f"worst {worst:.1f} s per 30 s of recording against the {BUDGET:.0f} s budget: "
          f"{'within' if worst <= BUDGET else 'OVER'}")


if __name__ == "__main__":
    main()

"""Validation speed: wall time of ``govcheck validate`` on a 30 s, 1 kHz recording (both modes).

Budget (issue 5): <= 5 s on 2 cores. Measured three ways:

- cold process: ``python -m compliance validate REC --plant plant-a --json OUT`` in a fresh
  interpreter (imports, numba cache load, reading, both replays, locate, metrics, JSON);
- in process, first call (after imports);
- in process, warm (best of 5).

The recording is the practice no-effect recording when ``../shared`` is beside the repository,
else a synthetic 30 s practice recording written to a temporary folder.

Run: .venv/bin/python benchmarks/validate_speed.py
Not part of the timed test suite.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def _recording(tmp: Path) -> Path:
    practice = ROOT.parent / "shared" / "practice-recordings" / "practice_no_effect.csv.gz"
    if practice.is_file():
        return practice
    from compliance.model.config import load_plant
    from compliance.recordings.synth import synthesise, write_recording

    rec, meta = synthesise(load_plant("plant-a"), x0=0.06, load=7000.0, kd=6.0, seed=1)
    path = tmp / "synthetic_practice.csv.gz"
    write_recording(rec, meta, path)
    return path


def main() -> None:
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        rec = _recording(tmp)
        out = tmp / "val.json"
        cmd = [sys.executable, "-m", "compliance", "validate", str(rec), "--plant", "plant-a", "--json", str(out)]
        subprocess.run(cmd, cwd=ROOT, capture_output=True, check=False)  # make sure the numba cache exists
        cold = []
        for _ in range(3):
            t0 = time.perf_counter()
            p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, check=False)
            cold.append(time.perf_counter() - t0)
            if p.returncode not in (0, 1):
                raise SystemExit(f"validate failed ({p.returncode}): {p.stderr}")
        from compliance.model.config import load_plant
        from compliance.recordings.reader import read_recording
        from compliance.validation.validate import validate

        cfg = load_plant("plant-a")
        t0 = time.perf_counter()
        df, meta = read_recording(rec)
        validate(cfg, df, meta)
        first = time.perf_counter() - t0
        warm = float("inf")
        for _ in range(5):
            t0 = time.perf_counter()
            df, meta = read_recording(rec)
            validate(cfg, df, meta)
            warm = min(warm, time.perf_counter() - t0)
        print(f"recording: {rec.name} ({len(df)} samples, {df['time'].iloc[-1] - df['time'].iloc[0]:.1f} s)")
        print(f"govcheck validate (fresh process, both modes, JSON): {min(cold):.2f} s best, {max(cold):.2f} s worst of 3")
        print(f"in process: first call {first:.2f} s, warm {warm:.2f} s (read + both replays + locate + metrics)")
        print(f"budget 5 s: {'OK' if max(cold) <= 5.0 else 'OVER'}")


if __name__ == "__main__":
    main()

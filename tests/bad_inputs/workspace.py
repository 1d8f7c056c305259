"""A small workspace of good inputs and good outputs that each bad-input case spoils one thing of.

Everything is written by code here (no binary fixtures): a plant configuration (the shipped
plant A), a one-requirement file, a 0.2 s closed-loop recording in every format govcheck
reads (canonical CSV + sidecar, .csv.gz, MATLAB .mat, COMTRADE .cfg/.dat, Parquet), a column
map, and good output files (JSON, HTML, PDF, CSV) that no failed run may touch.
"""

from __future__ import annotations

import gzip
import hashlib
import os
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
PLANT_A = (REPO / "models" / "plant-a.toml").read_text(encoding="utf-8")

REQUIREMENTS = '''schema = "govcheck-requirements/1"
name = "tiny"
title = "One requirement for the bad-input catalogue"

[operating_points.mid]
title = "Mid stroke, no load"
initial_position = "50 %stroke"
load = "none"

[procedures.steps-5]
kind = "steps"
title = "5 % steps"
size = "5 %stroke"

[requirements.TC]
title = "Time constant"
clause = "test"
metric = "time_constant"
comparator = "within"
limit = ["0.10 s", "0.25 s"]
procedures = ["steps-5"]
operating_points = ["mid"]
severity = "mandatory"
'''

SIDECAR = '''plant = "plant-a"
description = "bad-input catalogue: 0.2 s hold at 80 mm"
[conditions]
load_force = 7000.0
initial_position = 0.08
supply_pressure = 800000.0
[controller]
kp = 280.0
ki = 0.2
kd = 20.0
sample_time = 0.001
'''

COLUMN_MAP = '''[columns]
time = { column = "t_ms", unit = "ms" }
position = { column = "x_mm", unit = "mm" }
valve_command = { column = "u_V", unit = "V" }
pressure_a = { column = "pA_bar", unit = "bar", kind = "gauge" }
'''

N = 200  # samples at 1 kHz


def recording_columns() -> dict[str, np.ndarray]:
    """A quiet 0.2 s hold at 80 mm: canonical columns in SI."""
    t = np.arange(N) * 1e-3
    return {
        "time": t,
        "position": np.full(N, 0.08) + 1e-6 * np.sin(40 * t),
        "reference": np.full(N, 0.08),
        "valve_command": 0.01 * np.cos(30 * t),
        "pressure_a": np.full(N, 5.9e5),
        "pressure_b": np.full(N, 3.0e5),
        "supply_pressure": np.full(N, 8.0e5),
    }


def csv_text(cols: dict[str, np.ndarray] | None = None) -> str:
    """Canonical CSV text of ``cols`` (default: the good recording)."""
    cols = cols or recording_columns()
    names = list(cols)
    rows = [",".join(names)] + [",".join(f"{cols[n][i]:.9g}" for n in names) for i in range(len(cols["time"]))]
    return "\n".join(rows) + "\n"


def write_mat(path: Path, cols: dict[str, np.ndarray]) -> None:
    """MATLAB file with one variable per canonical column."""
    from scipy.io import savemat

    savemat(path, {k: np.asarray(v).reshape(-1, 1) for k, v in cols.items()})


def write_parquet(path: Path, cols: dict[str, np.ndarray]) -> None:
    """Parquet file with the canonical columns."""
    import pandas as pd

    pd.DataFrame(cols).to_parquet(path, index=False)


def write_comtrade(folder: Path, stem: str, cols: dict[str, np.ndarray], rate: float = 1000.0,
                   file_type: str = "ASCII", revision: str = "1999", ratios: dict | None = None) -> Path:
    """COMTRADE pair (analog channels named as the canonical columns, SI units) declaring ``rate`` [Hz]."""
    import pandas as pd

    from compliance.recordings.comtrade_write import comtrade_bytes

    frame = pd.DataFrame({**cols, "time": np.arange(len(cols["time"])) / rate})
    for suffix, data in comtrade_bytes(frame, station="bench", device="rig1", revision=revision, file_type=file_type,
                                       ratios=ratios).items():
        (folder / f"{stem}{suffix}").write_bytes(data)
    return folder / f"{stem}.cfg"


def build(ws: Path) -> None:
    """Write the good workspace into ``ws``."""
    (ws / "plant.toml").write_text(PLANT_A, encoding="utf-8")
    (ws / "req.toml").write_text(REQUIREMENTS, encoding="utf-8")
    (ws / "rec.csv").write_text(csv_text(), encoding="utf-8")
    (ws / "rec.toml").write_text(SIDECAR, encoding="utf-8")
    (ws / "map.toml").write_text(COLUMN_MAP, encoding="utf-8")
    out = ws / "out"
    out.mkdir()
    (out / "good.json").write_text('{"schema": "govcheck-results/1"}\n', encoding="utf-8")
    (out / "good.html").write_text("<html>good</html>\n", encoding="utf-8")
    (out / "good.pdf").write_bytes(b"%PDF-1.4 good\n")
    (out / "good.csv").write_text("time,position\n0,0\n", encoding="utf-8")
    (out / "a-folder.json").mkdir()
    (ws / "a-folder.json").mkdir()
    (out / "a-folder.html").mkdir()
    (out / "a-folder.pdf").mkdir()
    ro = out / "readonly.json"
    ro.write_text("{}\n", encoding="utf-8")
    ro.chmod(0o444)


def damaged_results(path: Path) -> None:
    """The shipped results fixture with text where the first requirement's worst value belongs (a hand edit)."""
    import json

    data = json.loads((REPO / "tests" / "data" / "results_fixture.json").read_text(encoding="utf-8"))
    data["requirements"][0]["worst"]["value"] = "lots"
    path.write_text(json.dumps(data), encoding="utf-8")


def gz(text: str) -> bytes:
    """Gzip bytes of ``text`` (fixed mtime)."""
    return gzip.compress(text.encode("utf-8"), mtime=0)


def tree_digest(root: Path) -> str:
    """SHA-256 over every path, file mode and file content under ``root`` (what 'nothing changed' means)."""
    h = hashlib.sha256()
    for dirpath, dirnames, filenames in os.walk(root):
        dirnames.sort()
        for name in sorted(filenames) + [d + "/" for d in dirnames]:
            p = Path(dirpath) / name.rstrip("/")
            rel = p.relative_to(root).as_posix()
            st = p.lstat()
            h.update(f"{rel}\0{st.st_mode:o}\0".encode())
            if p.is_file():
                h.update(p.read_bytes())
    return h.hexdigest()

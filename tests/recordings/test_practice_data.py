"""The shipped practice recordings (tests/data/practice) read cleanly and match their answers."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from compliance.recordings.reader import read_recording

PRACTICE = Path(__file__).resolve().parents[1] / "data" / "practice"
ANSWERS = json.loads((PRACTICE / "ANSWERS.json").read_text())


def test_answers_name_every_shipped_recording():
    names = {p.name[: -len(".csv.gz")] for p in PRACTICE.glob("*.csv.gz")}
    assert names == set(ANSWERS) and len(names) == 4
    assert sum(p.stat().st_size for p in PRACTICE.iterdir()) < 3e6  # small: a few MB at most


@pytest.mark.parametrize("name", sorted(ANSWERS))
def test_practice_recording_reads_with_its_sidecar(name):
    frame, meta = read_recording(PRACTICE / f"{name}.csv.gz")
    assert meta["plant"] == "plant-a" and meta["controller"]["sample_time"] == pytest.approx(1e-3)
    t = frame["time"].to_numpy()
    assert t[-1] == pytest.approx(30.0, abs=0.01) and np.median(np.diff(t)) == pytest.approx(1e-3)
    # plant A's stroke is 160 mm; the supply 8 bar abs within the logged noise
    assert 0.0 < frame["position"].min() and frame["position"].max() < 0.160
    assert frame["supply_pressure"].median() == pytest.approx(8.0e5, rel=0.01)

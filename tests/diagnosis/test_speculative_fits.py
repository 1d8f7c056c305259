"""Speculative second starts (``servo.diagnose``): what a diagnosis keeps does not depend on how many workers ran it.

In one process a candidate's second local fit runs after every first fit, and only where it still competes
(``fit.competing``); on two workers the second starts run beside the first fits as soon as each candidate's grid
is known, and only those that compete once every first fit is known are used and counted. Both must give the
same JSON (every fitted value, chi-square, score, verdict and the replay count), on the practice valve-dynamics
fixture with a library where two candidates have a second start: the spool lag's competes, the line's does not.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from compliance.diagnosis.servo.diagnose import diagnose
from compliance.diagnosis.servo.stage import Stage
from compliance.model.config import load_plant
from compliance.processes import AFTER
from compliance.recordings.reader import read_recording

DATA = Path(__file__).resolve().parents[1] / "data" / "practice"


def _without_timing(d) -> dict:
    def strip(x):
        if isinstance(x, dict):
            return {k: strip(v) for k, v in x.items() if k not in ("seconds", "jobs")}
        if isinstance(x, list):
            return [strip(v) for v in x]
        return "nan" if isinstance(x, float) and math.isnan(x) else x
    return strip(json.loads(json.dumps(d.to_dict())))


def test_speculative_second_starts_change_no_result(monkeypatch):
    """Reference: one process, the second starts a stage of their own after every first fit (no follow-ups).
    Speculative: two workers, every second start run to its end (more than the executor ever runs: the line's,
    which does not compete, finishes too); only the competing ones may be used and counted."""
    frame, meta = read_recording(DATA / "practice_valve_dynamics.csv.gz")
    cfg = load_plant("plant-a")
    calls = []
    run_fits = Stage.run_fits

    def spy(self, tasks, follow=None, wanted=None):
        tasks = list(tasks)
        if not speculate:
            follow = wanted = None
        elif follow is not None:
            wanted = lambda item: AFTER  # noqa: E731 - every follow-up runs to its end, used or not
        out = run_fits(self, tasks, follow, wanted)
        calls.append(([type(t).__name__ for t in tasks], [o is not None for o in out[len(tasks):]]))
        return out

    monkeypatch.setattr(Stage, "run_fits", spy)
    runs = {}
    for jobs, speculate in ((1, False), (2, True)):
        calls.clear()
        d = diagnose(cfg, frame, meta, effects=["valve_dynamics", "line_dynamics", "heat_transfer"], jobs=jobs,
                     recalibrate=False, stride=10)
        runs[jobs] = _without_timing(d)
        assert d.winner == "valve_dynamics" and d.verdict == "missing_physics"
        second_stage = any(tasks and set(tasks) == {"SecondStart"} for tasks, _ in calls)
        assert second_stage != speculate  # speculative: the spool lag's second start ran beside the first fits
        assert calls[0][1] == ([True, True] if speculate else [])  # the spool lag's and the line's second starts
    assert runs[1] == runs[2]

"""A step that never responded is the worst case of its row, not a gap (issue 22)."""

import dataclasses

from compliance.campaign.judge import judge_row
from compliance.procedures.outcomes import Sample
from compliance.requirements.loading import load_requirements
from compliance.units.amounts import parse_amount

MOVED = Sample(0.015, "step 1 of 2 up 1.60 mm at 1.00 s")
STILL = Sample(None, "step 2 of 2 down 1.60 mm at 5.00 s", "no motion beyond 0.016 mm after the step",
               detail={"non_responding": True})


def _deadtime(limit=None):
    req = [r for r in load_requirements("iec60308").requirements if r.id == "IEC60308-DEADTIME"][0]
    if limit is not None:
        req = dataclasses.replace(req, limit=(parse_amount(limit, "s", "test"),))
    return req


def test_open_limit_shows_the_silent_step_as_worst():
    row = judge_row(_deadtime(), "steps-1", "mid-stroke", None, [MOVED, STILL], None)
    assert row["status"] == "open" and row["which"].startswith("step 2") and "did not respond" in row["reason"]
    assert row["non_responding"] == [STILL.label]


def test_a_silent_step_fails_an_upper_limit_that_the_moving_one_passes():
    row = judge_row(_deadtime("0.05 s"), "steps-1", "mid-stroke", (0.05,), [MOVED, STILL], None)
    assert row["status"] == "fail" and row["value"] is None and "beyond any upper limit" in row["reason"]
    only_moved = judge_row(_deadtime("0.05 s"), "steps-1", "mid-stroke", (0.05,), [MOVED], None)
    assert only_moved["status"] == "pass"

"""Scoring practice recordings: the answers' ``accept`` rule for truths that are not plant physics, the table."""

from __future__ import annotations

from types import SimpleNamespace

from compliance.diagnosis.scoring.practice_score import practice_correct, practice_table

SENSOR = {"verdicts": ["no_mismatch", "parameters_only", "unexplained"], "named": ["time_offset", "skew"]}
NONE = {"verdicts": ["no_mismatch", "unexplained"]}


def _d(verdict, winner=None):
    return SimpleNamespace(verdict=verdict, winner=winner, ambiguous=[])


def test_a_sensor_only_truth_is_right_without_a_physical_claim():
    assert practice_correct(_d("no_mismatch"), ["sensor:time_offset"], SENSOR) == (True, False)
    assert practice_correct(_d("instrumentation", "instrument:pressure_time_offset"), ["sensor:time_offset"], SENSOR)[0]
    assert not practice_correct(_d("missing_physics", "sensor_lag"), ["sensor:time_offset"], SENSOR)[0]
    assert not practice_correct(_d("ambiguous", "valve_dynamics"), ["sensor:time_offset"], SENSOR)[0]
    assert not practice_correct(_d("instrumentation", "instrument:pressure_gain"), ["sensor:time_offset"], SENSOR)[0]


def test_no_truth_with_accept_refuses_a_recalibration():
    assert practice_correct(_d("unexplained"), [], NONE)[0]
    assert not practice_correct(_d("parameters_only", "base"), [], NONE)[0]
    assert practice_correct(_d("parameters_only", "base"), [])[0]  # the plain rule (no accept) allows it


def test_practice_table_is_markdown_with_one_row_per_recording():
    rep = {"correct": 1, "recordings": [
        {"name": "a", "truth": "none", "verdict": "no_mismatch", "winner": None, "correct": True,
         "objective_before": {"position": 1.1, "valve_command": 0.9}, "objective_after": None, "main": None, "seconds": 12.0},
        {"name": "b", "truth": "valve_offset", "verdict": "missing_physics", "winner": "valve_offset", "correct": False,
         "objective_after": {"position": 1.4}, "main": {"parameter": "u0", "error": 0.5}, "seconds": 30.0}]}
    text = practice_table(rep)
    assert "| a | none | no_mismatch | - | yes | 1.10 (position) | - | 12 |" in text
    assert "| b | valve_offset | missing_physics | valve_offset | no | 1.40 (position) | 50 % (u0) | 30 |" in text
    assert text.endswith("1/2 right.")

"""``diagnose-benchmark --markdown``: the results as Markdown tables, checked and written like every output."""

from __future__ import annotations

from pathlib import Path

import pytest

from compliance.cli import main

PRACTICE = str(Path(__file__).resolve().parents[1] / "data" / "practice")
REP = {"correct": 1, "main_scored": 1, "main_within_25": 1, "main_split_open_interval_contains_truth": 0,
       "recordings": [{"name": "practice_valve_offset", "truth": "valve_offset", "verdict": "missing_physics",
                       "winner": "valve_offset", "correct": True, "ambiguous_with_truth": False,
                       "objective_after": {"position": 1.21}, "main": {"parameter": "u0", "error": 0.02},
                       "seconds": 31.0, "parameters": {}}]}


@pytest.fixture
def fake_practice(monkeypatch):
    import compliance.diagnosis.scoring.benchmark as benchmark

    calls = []
    monkeypatch.setattr(benchmark, "run_practice", lambda *a, **k: calls.append(a) or REP)
    return calls


def test_practice_results_are_written_as_markdown_without_times_when_reproducible(tmp_path, fake_practice, capsys):
    out = tmp_path / "practice.md"
    code = main(["diagnose-benchmark", "--practice", PRACTICE, "--markdown", str(out), "--reproducible", "-j", "1"])
    capsys.readouterr()
    assert code == 0 and len(fake_practice) == 1
    text = out.read_text()
    assert "| practice_valve_offset | valve_offset | missing_physics | valve_offset | yes | 1.21 (position) | 2.0 % (u0) |\n" in text
    assert " s |" not in text and "31" not in text  # no wall-time column: the same text on every run
    assert "1/1 right." in text and "Main parameter within 25 % of the truth: 1 of 1." in text


@pytest.mark.parametrize("name", ["practice.txt", "no-such-folder/practice.md"])
def test_a_bad_markdown_path_is_refused_before_any_work(tmp_path, fake_practice, capsys, name):
    code = main(["diagnose-benchmark", "--practice", PRACTICE, "--markdown", str(tmp_path / name)])
    err = capsys.readouterr().err
    assert code == 2 and "--markdown" in err
    assert not fake_practice and not list(tmp_path.iterdir())

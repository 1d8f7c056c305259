"""diagnose --save-model after a no_mismatch verdict: exit 0, JSON written, a note instead of an error."""

from __future__ import annotations

import json
from pathlib import Path

from compliance.cli import main
from tests.bad_inputs import workspace as W


class _NoMismatch:
    verdict, fitted_cfg, saved_model = "no_mismatch", None, None

    def to_dict(self):
        return {"schema": "govcheck-diagnosis/1", "verdict": "no_mismatch", "winner": None, "reason": "fits within the noise", "explanation": "nothing missing",
                "effects": [], "fit_before": {}, "fit_after": None, "windows": [],
                "timing": {"seconds": 1.0, "simulations": 1, "jobs": 1}}


def test_save_model_after_no_mismatch_is_a_note(tmp_path, monkeypatch, capsys):
    import compliance.diagnosis.servo.diagnose as engine

    W.build(tmp_path)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(engine, "diagnose", lambda *a, **k: _NoMismatch())
    code = main(["diagnose", "plant.toml", "rec.csv", "--save-model", "fitted.toml", "--json", "d.json", "--reproducible"])
    out = capsys.readouterr().out
    assert code == 0
    assert "not written: the verdict is 'no_mismatch'" in out
    assert not Path("fitted.toml").exists()
    data = json.loads(Path("d.json").read_text())
    assert data["verdict"] == "no_mismatch" and "timing" not in data and data["created"].startswith("1970")

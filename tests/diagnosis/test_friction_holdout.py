"""Out-of-sample proof of the seal-friction law (friction_bench/holdout.py) and the declared position_dependent_friction.

Synthetic bench runs made from a known law with seeded force noise: a law that is the truth must
predict a pressure it was not fitted on to the noise, and the position effect must earn its
parameters held out exactly when the runs carry it. Then the real bench fixture (four O-ring runs).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from compliance.characterise.friction_map import piston_area, synthetic_friction_run
from compliance.diagnosis.friction_bench.diagnose import FRICTION_RESIDUAL_LIMIT, diagnose_friction
from compliance.diagnosis.friction_bench.runs import prepare_runs
from compliance.diagnosis.friction_bench.fit import fit_law
from compliance.diagnosis.friction_bench.holdout import earns, prove_out_of_sample
from compliance.diagnosis.friction_bench.laws import position_factor

DATA = Path(__file__).resolve().parents[1] / "data"
NOISE = 0.05  # N, force noise of the synthetic runs
LAW = {"coulomb": 3.0, "static": 4.0, "stribeck_velocity": 0.003, "viscous": 80.0}
KP = 2e-6  # N/Pa


def _runs(gradient: float):
    """Four runs (1, 3, 5, 7 bar) of a seal whose friction levels scale by 1 + gradient (x - 20 mm)."""
    area = piston_area(0.0257)
    out = []
    for i, bar in enumerate((1.0, 3.0, 5.0, 7.0)):
        f = synthetic_friction_run([0.005, 0.015], LAW, area=area, pressure_gauge=bar * 1e5, seed=i, pressure_coefficient=KP)
        x = f["position"].to_numpy()
        friction = f["force"].to_numpy() - bar * 1e5 * area
        scale = position_factor(x, {"position_gradient": gradient, "reference_position": 0.02})
        # the viscous part does not scale with the squeeze (the law scales the Stribeck levels only)
        v = np.gradient(x, f["time"].to_numpy())
        friction = (friction - LAW["viscous"] * v) * scale + LAW["viscous"] * v
        f["force"] = friction + bar * 1e5 * area + np.random.default_rng(10 + i).normal(0.0, NOISE, x.size)
        out.append((f, {"source_path": f"seal_{bar:.0f}bar.csv", "bore": 0.0257}))
    return prepare_runs(out, None)


def test_true_law_predicts_held_out_pressures_to_the_noise_and_position_effect_earns_its_place():
    """Levels falling 1 % per mm along the stroke: the pressure law alone predicts each held-out pressure poorly,
    with position_dependent_friction it predicts them as well as the runs it saw, within the 3 x force noise a complete
    law leaves (friction_diagnosis.FRICTION_RESIDUAL_LIMIT: the law is evaluated on a differentiated velocity), and
    the effect is kept."""
    runs = _runs(-10.0)
    fits = {"pressure_dependent_friction": fit_law(runs, "pressure_dependent_friction")}
    proof = prove_out_of_sample(runs, fits, "pressure_dependent_friction", True, jobs=1)
    pos = proof["position"]
    assert pos["earned"] and proof["law"].endswith("position_dependent_friction")
    assert pos["runs_improved"] == 4 and pos["median_gain"] > 0.3
    assert fits[proof["law"]].params["position_gradient"] == pytest.approx(-10.0, rel=0.1)
    table = proof["holdout"]
    assert len(table["runs"]) == 4
    for row in table["runs"]:
        assert row["held_out_rms"] < FRICTION_RESIDUAL_LIMIT * NOISE
        assert row["ratio"] < 1.1  # a true law predicts a pressure it did not see as well as the ones it saw
    assert table["within_target"]


def test_position_effect_not_kept_when_the_runs_have_none():
    runs = _runs(0.0)
    fits = {"pressure_dependent_friction": fit_law(runs, "pressure_dependent_friction")}
    proof = prove_out_of_sample(runs, fits, "pressure_dependent_friction", True, jobs=1)
    assert not proof["position"]["earned"]
    assert proof["law"] == "pressure_dependent_friction" and len(fits) == 1  # the rejected candidate is not ranked
    assert proof["holdout"]["median_ratio"] < 1.1
    assert max(r["held_out_rms"] for r in proof["holdout"]["runs"]) < FRICTION_RESIDUAL_LIMIT * NOISE


def test_earns_needs_most_runs_and_a_median_gain():
    def table(values):
        return {"runs": [{"held_out_rms": v} for v in values]}

    assert earns(table([0.9, 0.9, 0.9, 0.9]), table([1.0, 1.0, 1.0, 1.0]))["earned"]
    assert not earns(table([0.9, 0.9, 1.1, 1.1]), table([1.0, 1.0, 1.0, 1.0]))["earned"]  # 2 of 4 runs
    assert not earns(table([0.98, 0.98, 0.98, 0.98]), table([1.0, 1.0, 1.0, 1.0]))["earned"]  # 2 % gain only


def test_real_o_ring_fixture_held_out_table(tmp_path):
    """Four real O-ring runs (heads of the 1, 3, 5, 7 bar files): every pressure predicted by the law fitted on
    the other three. Measured: median held-out / in-sample 1.5 with each run's force zero as fitted, 1.2 with the
    held-out run's own zero (the run-to-run offsets of up to ~1 N are the bench's, reported, not modelled)."""
    from compliance.recordings.reader import read_recording

    files = sorted((DATA / "zillen").glob("O-ring257_*bar_head1000.csv"))
    assert len(files) == 4
    diag = diagnose_friction([read_recording(f, "zillen-friction", required=("time",)) for f in files], jobs=1)
    d = diag.to_dict()
    (seal,) = d["seals"]
    h = seal["holdout"]
    assert [round(r["pressure_gauge"] / 1e5) for r in h["runs"]] == [1, 3, 5, 7]
    for r in h["runs"]:
        assert r["held_out_rms"] >= 0.95 * r["in_sample_rms"]  # out of sample is never clearly better than in sample
        assert 3.0 < r["held_out_in_noise"] < 40.0  # the law is not complete: several times the force noise
    assert h["median_ratio_without_offset"] <= 1.5
    assert h["median_ratio"] <= 2.0
    assert seal["position_effect"]["runs"] == 4
    assert "Out of sample" in seal["explanation"]
    from compliance.report.friction import write_friction_report

    html = write_friction_report(diag, tmp_path / "f.html").read_text()
    assert "Out of sample: each pressure predicted" in html and "O-ring257_7bar_head1000.csv" in html

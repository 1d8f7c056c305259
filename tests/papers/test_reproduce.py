"""The paper comparison (govcheck reproduce) runs end to end and respects the dead-zone stall physics."""

from __future__ import annotations

import pytest

from compliance.cli import main
from compliance.model.config import load_plant
from compliance.model.pid_controller import stall_error
from compliance.papers.plant_a import CASES, _step_metrics


def test_stall_error_formula():
    cfg = load_plant("plant-a")
    # reference-plant.md: zmd*lc/((zmd + lc)*K_P) = 0.61*0.4/(1.01*280) = 0.863 mm
    assert stall_error(cfg) == pytest.approx(0.61 * 0.4 / (1.01 * 280.0), rel=1e-12)


def test_steady_errors_stay_inside_the_stall_band():
    """With an ideal dead zone the valve shuts only inside the stall band, so no steady error may exceed it
    by more than the pre-sliding creep after the valve shuts (F_S/sigma0 per cylinder = 0.42 mm is an upper bound)."""
    cfg = load_plant("plant-a")
    band = stall_error(cfg)
    for case in CASES[:3]:
        for m in _step_metrics(cfg, case):
            assert m.steady_state_error <= band + 0.42e-3


def test_reproduce_cli(capsys):
    assert main(["reproduce", "plant-a", "--no-explain"]) == 0
    out = capsys.readouterr().out
    for text in ("fig. 9", "fig. 10", "fig. 11", "fig. 12", "opening time t_a", "settling time", "steady error"):
        assert text in out

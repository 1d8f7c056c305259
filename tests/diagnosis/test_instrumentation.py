"""Instrumentation findings: a channel group logged late or a pressure transducer's gain error is never plant physics."""

from __future__ import annotations

import numpy as np
import pytest

from compliance.diagnosis.servo.diagnose import diagnose
from compliance.diagnosis.servo.instrument_candidates import instrument_candidates, instrumented
from compliance.diagnosis.scoring.practice_score import practice_correct
from compliance.validation.replay import prepare_replay
from compliance.model.config import load_plant
from compliance.recordings.synth import PRACTICE_NOISE, synthesise

PLANT_RIVALS = ["sensor_lag", "valve_dynamics", "internal_leakage", "line_dynamics"]


@pytest.fixture(scope="module")
def cfg():
    return load_plant("plant-a")


@pytest.fixture(scope="module")
def recording(cfg):
    return synthesise(cfg, "steps", x0=0.06, load=7000.0, kd=20.0, noise=PRACTICE_NOISE, seed=5, duration=17.0)


def test_candidates_follow_the_channels_and_act_on_the_logger_only(cfg, recording):
    frame, meta = recording
    names = [c.name for c in instrument_candidates(("position", "valve_command", "pressure_b"), True)]
    assert names == ["instrument:pressure_time_offset", "instrument:pressure_gain", "instrument:position_time_offset",
                     "instrument:logger_delay"]
    assert [c.name for c in instrument_candidates(("position", "valve_command"), True)][0] == "instrument:position_time_offset"
    setup = prepare_replay(cfg, frame, meta)
    cand = instrument_candidates(("position", "pressure_a"), True)[0]
    moved = instrumented(setup, cand.params, [0.003])
    assert moved.logger.delay["pressure_a"] == 0.003 and setup.logger is None


@pytest.mark.slow
def test_pressures_logged_late_are_an_instrumentation_finding(cfg, recording):
    """Pressures on a second module 8 ms late: the verdict says so, and no plant effect is claimed."""
    frame, meta = recording
    late = frame.copy()
    t = frame["time"].to_numpy()
    for s in ("pressure_a", "pressure_b", "supply_pressure"):
        if s in late:
            late[s] = np.interp(t - 0.008, t, frame[s].to_numpy())
    d = diagnose(cfg, late, meta, effects=PLANT_RIVALS, jobs=1, recalibrate=False)
    assert d.verdict == "instrumentation" and d.winner == "instrument:pressure_time_offset"
    assert d.fits[d.winner].values[0] == pytest.approx(0.008, abs=0.0015)
    assert "check your instrumentation" in d.explanation.lower()
    accept = {"verdicts": ["no_mismatch", "parameters_only", "unexplained"], "named": ["time_offset"]}
    assert practice_correct(d, ["sensor:time_offset"], accept) == (True, False)



def test_re_synchronisations_read_the_plant_through_the_instrument_taken_back(cfg, recording):
    """A pressure logged 2 % high (gauge) and 5 ms late: the states a candidate's replay resets to are the plant's."""
    frame, meta = recording
    setup = prepare_replay(cfg, frame, meta)
    cand = instrument_candidates(("position", "valve_command", "pressure_b"), True)
    gain = instrumented(setup, cand[1].params, [1.02])
    pb = setup.states["pressure_b"]
    assert np.allclose(101325.0 + 1.02 * (gain.states["pressure_b"] - 101325.0), pb)
    late = instrumented(setup, cand[0].params, [0.005])
    assert late.states["pressure_b"][1000] == pytest.approx(pb[1005])
    assert late.states["position"] is setup.states["position"]

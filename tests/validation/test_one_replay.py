"""One replay for validate and diagnose (compliance/validation/replay.py): the same residual, mixed segments, full scale."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from compliance.diagnosis.evidence.residuals import signal_fit as diagnosis_fit
from compliance.diagnosis.servo.stage import prepare_recording
from compliance.model.config import load_plant
from compliance.recordings.reader import read_recording
from compliance.validation.replay import prepare_replay, replay, run_replay
from compliance.validation.replay_setup import SATURATED_RUN, full_scale
from compliance.validation.settings import ValidationSettings
from compliance.validation.validate import validate

DATA = Path(__file__).resolve().parents[1] / "data"
PRACTICE = DATA / "practice" / "practice_internal_leakage.csv.gz"
HOLD = DATA / "acceptance" / "site-p2-hold_1-head4s.csv.gz"


@pytest.fixture(scope="module")
def plant():
    return load_plant("plant-a")


@pytest.mark.parametrize("path", [PRACTICE, HOLD], ids=["closed_loop_1kHz", "hold_500Hz_mixed"])
def test_validate_and_diagnose_give_the_same_residual(plant, path):
    frame, meta = read_recording(path)
    checked = validate(plant, frame, meta, ValidationSettings(modes=("closed_loop",)))["modes"]["closed_loop"]["fits"]
    st = prepare_recording(plant, frame, meta, 5, 1)
    whole = run_replay(st.rc, dataclasses.replace(st.setup, resets=np.array([0, st.setup.command_from])
                                                  if 0 < st.setup.command_from < st.setup.time.size else np.array([0])))
    mine = diagnosis_fit(st.model, whole)
    if st.setup.logged is None:  # on the controller clock: the very same samples, so the very same numbers
        for s, v in mine.items():
            assert v["nrmse"] == pytest.approx(checked[s]["nrmse"], rel=1e-9, abs=1e-12), s
    # the validation's replay at the recording's own time stamps is the diagnosis's at the logged instants
    sim = replay(plant, frame, meta, "closed_loop")
    k = st.setup.samples
    for s in ("position", "pressure_a", "pressure_b", "valve_command"):
        assert np.allclose(sim[s].to_numpy(), whole[s][k][: len(sim)], rtol=0.0, atol=1e-12), s


def test_a_hold_is_closed_loop_until_the_positioner_goes_to_manual(plant):
    frame, meta = read_recording(HOLD)
    setup = prepare_replay(plant, frame, meta, segmented=False)  # validation's replay: in one piece but for the switch
    ts = plant.p("controller.sample_time")
    assert setup.command_from == int(round(meta["test"]["valve_null_from"] / ts))  # 1.0 s on the 1 ms controller clock
    assert list(setup.resets) == [0, setup.command_from]  # the mode switch starts a segment
    assert setup.command_from in prepare_replay(plant, frame, meta).resets  # and so it does among the diagnosis's
    assert setup.flow_control is True  # sidecar test.flow_control = "set"
    assert not np.any(setup.noise[setup.command_from:])  # no controller to feed noise to after the switch
    sim = run_replay(setup.config(plant), setup)
    before, after = slice(100, setup.command_from - 1), slice(setup.command_from + 1, None)
    # the model's PID acts until the switch (its command dithers around the dead band), then the recorded 0 V drives
    assert np.std(sim["valve_command"][before]) > 0.05
    assert np.array_equal(sim["valve_command"][after], setup.command[after])
    assert not np.any(setup.command[after])
    # the recording drifts with the valve shut and its pressures fall (the site's external leak: 0.25 mm and 40 kPa
    # in these 3 s); the nominal model, leak-free, holds: position and pressures flat
    drift = setup.recorded["position"][-200:].mean() - setup.recorded["position"][setup.command_from:setup.command_from + 200].mean()
    assert drift < -1e-4
    model_drift = sim["position_true"][-1] - sim["position_true"][setup.command_from + 1]
    assert abs(model_drift) < 0.01 * abs(drift)
    fall = setup.recorded["pressure_a"][setup.command_from] - setup.recorded["pressure_a"][-1]
    assert fall > 3e4 and abs(sim["pressure_a"][-1] - sim["pressure_a"][setup.command_from + 1]) < 0.01 * fall


def test_a_transducer_at_full_scale_is_found_and_the_model_clipped_alike(plant):
    v = np.linspace(5e5, 1.2e6, 400) + np.random.default_rng(1).normal(0.0, 300.0, 400)
    clipped = np.minimum(v, 1e6)
    found = full_scale({"pressure_a": clipped, "pressure_b": v}, None)
    assert found == {"pressure_a": (None, 1e6)}  # a live reading never repeats its maximum SATURATED_RUN times
    assert np.count_nonzero(clipped == 1e6) >= SATURATED_RUN


def test_a_hold_tests_command_floor_is_the_controllers(plant):
    frame, meta = read_recording(HOLD)
    result = validate(plant, frame, meta, ValidationSettings(modes=("closed_loop",)))
    # the controller's command dithers by ~0.3 V around the dead band until the switch; the 0 V written after it is
    # the replay's input, not a measurement: a floor from it (its quantisation, 0.1 mV) would flag every dither
    assert result["noise_floors"]["valve_command"]["value"] > 0.05
    assert result["conditions"]["command_from"] == pytest.approx(1.0)

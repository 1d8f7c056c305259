"""What the compiled loops are fed and what they hand back: profile samples, the output frame's layout."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numba import types

from compliance.diagnosis.evidence.replay_fit import prepare_replay, replay_config, run_replay
from compliance.model.config import load_plant
from compliance.recordings.reader import read_recording
from compliance.simulation import OUTPUT_COLUMNS, Scenario, simulate
from compliance.simulation.pid_loop import simulate_core
from compliance.simulation.profiles import Profile, sine, steps
from compliance.simulation.rk4 import output_buffer

STROKE = 0.160
PRACTICE = Path(__file__).resolve().parents[1] / "data" / "practice"


def _plain_at(profile: Profile, t: np.ndarray) -> np.ndarray:
    """The piecewise-linear definition written with numpy (the last sample at or before t starts the segment)."""
    times, values = profile.times, profile.values
    i = np.clip(np.searchsorted(times, t, side="right") - 1, 0, times.size - 1)
    j = np.clip(i + 1, 0, times.size - 1)
    rising = times[j] > times[i]
    w = np.where(rising, np.clip((t - times[i]) / np.where(rising, times[j] - times[i], 1.0), 0.0, 1.0), 0.0)
    return np.where(t < times[0], values[0], values[i] + w * (values[j] - values[i]))


@pytest.mark.parametrize("profile", [
    steps("2%@1s,-2%@1s,5%@3s", 0.05, STROKE),  # a step and its undoing at one instant
    sine(8e-3, 0.05, 0.08, start=2.0, duration=30.0),
    Profile.constant(3.0),
    Profile(np.array([1.0, 1.0, 2.0]), np.array([0.0, 1.0, 3.0])),  # starts with a step, after t = 0
])
def test_profile_samples_are_the_piecewise_linear_definition_bit_for_bit(profile):
    grid = np.arange(4001) * 1e-3 - 0.5  # the controller grid, from before the first sample
    shuffled = np.random.default_rng(4).uniform(-1.0, 35.0, 3000)  # any order, beyond the last sample
    edges = np.array([np.nan, np.inf, -np.inf, 1.0, 2.0, 3.0, 0.0])
    for t in (grid, shuffled, edges):
        assert np.array_equal(profile.at(t), _plain_at(profile, t), equal_nan=True)
        assert np.array_equal(profile.at(t).view(np.int64), _plain_at(profile, t).view(np.int64))  # signed zeros too
    assert profile.at(1.0).shape == ()  # a scalar time gives a scalar sample
    # a step takes its new value at its instant, the value before it holds until then
    st = steps("2%@1s", 0.05, STROKE)
    assert st.at(np.array([1.0 - 1e-12, 1.0])).tolist() == [0.05, 0.05 + 0.02 * STROKE]


def test_output_frame_columns_are_contiguous_and_each_run_owns_its_memory():
    cfg = load_plant("plant-a")
    sc = Scenario(duration=0.3, initial_position=0.08, reference=steps("2%@0.1s", 0.08, STROKE), load=7000.0)
    a, b = simulate(cfg, sc), simulate(cfg, sc)
    assert list(a.columns) == list(OUTPUT_COLUMNS) and len(a) == 301
    for name in OUTPUT_COLUMNS:
        assert a[name].to_numpy().flags.c_contiguous  # the loop wrote it by column: no copy, no stride
    assert not np.shares_memory(a["position"].to_numpy(), b["position"].to_numpy())
    a["position"] = 0.0
    a.columns.name = "renamed"
    assert b["position"].iloc[-1] > 0.08 and b.columns.name is None  # one run's frame never changes another's
    assert simulate(cfg, sc).columns.name is None


def test_simulate_and_the_diagnosis_replay_compile_the_loop_once():
    """simulate and the diagnosis replay hand the loop the same argument types, so it is compiled once."""
    cfg = load_plant("plant-a")
    simulate(cfg, Scenario(duration=0.05, initial_position=0.08))
    frame, meta = read_recording(str(PRACTICE / "practice_no_effect.csv.gz"))
    setup = prepare_replay(cfg, frame.iloc[:2000].reset_index(drop=True), meta)
    run_replay(replay_config(cfg, setup), setup)
    layouts = {sig[-1].layout for sig in simulate_core.signatures}
    assert output_buffer(2).flags.f_contiguous and layouts == {"F"}
    # nor read-only inputs (pandas' to_numpy gives read-only arrays): each would compile the loop again
    assert all(arg.mutable for sig in simulate_core.signatures for arg in sig if isinstance(arg, types.Array))

"""What the compiled loops are fed and what they hand back: profile samples, the output frame's layout."""

from __future__ import annotations

import numpy as np
import pytest
import numba

from compliance.model.config import load_plant
from compliance.plants import simulate
from compliance.simulation import OUTPUT_COLUMNS, Scenario, SensorNoise
from compliance.simulation import pid_loop
from compliance.simulation.pid_loop import simulate_core
from compliance.simulation.profiles import Profile, sine, steps
from compliance.simulation.rk4 import output_buffer

STROKE = 0.160


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


def test_every_simulate_path_hands_the_loop_one_set_of_argument_types(monkeypatch):
    """Closed loop, plant-only, seeded and given noise: one compiled loop (each variant costs seconds to compile)."""
    seen = set()

    def typed(*args):
        seen.add(tuple(numba.typeof(a) for a in args))
        return simulate_core(*args)

    monkeypatch.setattr(pid_loop, "simulate_core", typed)
    cfg = load_plant("plant-a")
    st = steps("2%@0.02s", 0.08, STROKE)
    cmd = Profile(np.array([0.0, 0.02, 0.02]), np.array([5.0, 5.0, 6.0]))
    for sc in (Scenario(duration=0.05, initial_position=0.08, reference=st, load=7000.0),
               Scenario(duration=0.05, initial_position=0.08, command=cmd, load="curve"),
               Scenario(duration=0.05, initial_position=0.08, reference=st, noise=SensorNoise(1e-5, 1e-6, 100.0, 10.0)),
               Scenario(duration=0.05, initial_position=0.08, reference=st, position_noise=np.zeros(20))):
        simulate(cfg, sc)
    assert len(seen) == 1
    (sig,) = seen
    assert sig[-1].layout == "F" and output_buffer(2).flags.f_contiguous  # the output by column
    assert all(arg.mutable for arg in sig if isinstance(arg, numba.types.Array))  # read-only arrays compile anew

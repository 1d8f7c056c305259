"""Stroke timing by the definition a requirement names (metrics.stroke_figures / timed), on traces with known answers.

Synthetic strokes of a 160 mm servomotor sampled every 1 ms: the crossings are interpolated, so every
figure is exact to well under one sample (1 ms); the tolerances below are 2 ms.
"""

import numpy as np
import pytest

from compliance.metrics.stroke import STRAIGHT_TOLERANCE, stroke_figures, timed

L = 0.160
DT = 1e-3


def _ramp(delay, speed, t_end=12.0):
    """Opening stroke: rest for ``delay``, then constant ``speed`` to the end stop."""
    t = np.arange(0.0, t_end, DT)
    return t, np.clip((t - delay) * speed, 0.0, L)


def _surge(delay, v_fast, v_slow, x_switch, t_end=20.0):
    """Closing stroke from L: ``v_fast`` over the first ``x_switch`` of travel, then ``v_slow`` (a meter-out surge)."""
    t = np.arange(0.0, t_end, DT)
    t1 = delay + x_switch / v_fast
    travel = np.where(t < delay, 0.0, np.where(t < t1, (t - delay) * v_fast, x_switch + (t - t1) * v_slow))
    return t, L - np.clip(travel, 0.0, L)


def test_straight_stroke_full_rate_is_the_stroke_at_its_rate():
    delay, v = 0.40, 0.032  # 5 s at full rate, 0.4 s start delay
    t, x = _ramp(delay, v)
    f = stroke_figures(t, x, L, "opening")
    assert f["straight"] is True
    assert f["quarter_speeds"][0] == pytest.approx(v, rel=1e-3) and f["quarter_speeds"][1] == pytest.approx(v, rel=1e-3)
    val, note, used = timed(f, "full_rate")
    assert used == "full_rate" and note is None and val == pytest.approx(L / v, abs=2e-3)
    # the start delay and the end are timed apart: command -> 1 % and command -> 99 % of the travel
    assert f["start_delay"] == pytest.approx(delay + 0.01 * L / v, abs=2e-3)
    assert timed(f, "end_to_end")[0] == pytest.approx(delay + 0.99 * L / v, abs=2e-3)
    assert f["cushion_time"] == pytest.approx(0.09 * L / v, abs=2e-3) == pytest.approx(f["cushion_at_rate"], abs=2e-3)


def test_stroke_with_no_straight_part_is_flagged_and_timed_end_to_end():
    # plant A closing at 12 kN: a surge, then the throttle's rate; quarter speeds differ by far more than 20 %
    delay, fast, slow = 0.17, 0.090, 0.027
    t, x = _surge(delay, fast, slow, 0.5 * L)
    f = stroke_figures(t, x, L, "closing")
    assert f["straight"] is False
    v1, v2 = f["quarter_speeds"]
    assert v1 == pytest.approx(fast, rel=1e-3) and v2 == pytest.approx(slow, rel=1e-3)
    end = delay + 0.5 * L / fast + 0.49 * L / slow
    val, note, used = timed(f, "full_rate")
    assert used == "end_to_end" and note.startswith("no straight part") and val == pytest.approx(end, abs=2e-3)
    # the 25-75 % rule extrapolates an average of the middle half: 2 x (0.25 L / fast + 0.25 L / slow)
    assert timed(f, "extrapolated")[0] == pytest.approx(2 * (0.25 * L / fast + 0.25 * L / slow), abs=2e-3)


def test_straightness_threshold_sits_where_it_says():
    # quarter speeds v and v (1 + d): straight while |d| / mean <= STRAIGHT_TOLERANCE
    for d, straight in ((0.9 * STRAIGHT_TOLERANCE, True), (1.2 * STRAIGHT_TOLERANCE, False)):
        v = 0.030
        t, x = _surge(0.2, v * (1 + d), v, 0.5 * L)  # fast up to 50 % of the travel, slower after
        f = stroke_figures(t, x, L, "closing")
        assert f["straight"] is straight, d


def test_command_time_and_a_stroke_that_never_ends():
    t, x = _ramp(1.0, 0.032)
    f = stroke_figures(t, x, L, "opening", t_command=0.5)
    assert f["start_delay"] == pytest.approx(0.5 + 0.01 * L / 0.032, abs=2e-3)
    t, x = _ramp(0.3, 0.010, t_end=13.0)  # 16 s stroke cut at 13 s: passes 75 % (12.3 s), never reaches the end
    f = stroke_figures(t, x, L, "opening")
    assert f["extrapolated"] == pytest.approx(L / 0.010, abs=2e-3)
    val, note, _ = timed(f, "end_to_end")
    assert val is None and "99 %" in note

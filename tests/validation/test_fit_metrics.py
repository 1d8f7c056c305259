"""Fit and windowed error measures (compliance.validation.fit_metrics) and validation settings."""

from __future__ import annotations

import math

import numpy as np
import pytest

from compliance.model.config import load_plant
from compliance.errors import InputError
from compliance.recordings.synth import practice_profile
from compliance.validation.validate import apply_overrides, decimation_indices, load_settings, settings_from_dict
from compliance.validation.fit_metrics import (
    DEFAULT_LIMITS,
    ErrorLimits,
    ErrorWindow,
    MetricSettings,
    assess,
    derive_windows,
    error_measures,
    filtered_error,
    fit_percent,
    nrmse,
    per_unit_bases,
    window_metrics,
)


def test_fit_and_nrmse_hand_values():
    y = np.array([0.0, 1.0, 2.0, 3.0])
    yhat = y + np.array([0.1, -0.1, 0.1, -0.1])
    # ||e|| = 0.2, ||y - mean|| = sqrt(2.25 + 0.25 + 0.25 + 2.25) = sqrt(5)
    assert nrmse(y, yhat) == pytest.approx(0.2 / math.sqrt(5.0), rel=1e-12)
    assert fit_percent(y, yhat) == pytest.approx(100.0 * (1.0 - 0.2 / math.sqrt(5.0)), rel=1e-12)
    assert fit_percent(y, y) == 100.0
    assert fit_percent(y, np.full(4, 1.5)) == pytest.approx(0.0, abs=1e-12)  # the mean: 0 %
    assert fit_percent(np.ones(5), np.zeros(5)) is None  # constant recording: undefined


def test_error_measures_and_assessment():
    e = np.array([0.1, -0.3, 0.2])
    m = error_measures(e)
    assert m["max_error"] == pytest.approx(0.3)
    assert m["mean_error"] == pytest.approx(0.0, abs=1e-15)
    assert m["mean_absolute_error"] == pytest.approx(0.2)
    ok, failed = assess(m, ErrorLimits(max_error=0.25, mean_error=0.01, mean_absolute_error=0.21))
    assert not ok and failed == ["max_error"]
    ok, failed = assess({"max_error": 0.1, "mean_error": -0.05, "mean_absolute_error": 0.05}, ErrorLimits(None, 0.04, None))
    assert not ok and failed == ["mean_error"]  # |ME| is compared
    assert assess(m, None) == (True, [])


def test_per_unit_bases_of_plant_a():
    b = per_unit_bases(load_plant("plant-a"))
    assert b["position"]["value"] == pytest.approx(0.160)
    assert b["valve_command"]["value"] == pytest.approx(10.0)
    assert b["pressure_a"]["value"] == pytest.approx(8.0e5)
    assert per_unit_bases(load_plant("plant-a"), 7.0e5)["pressure_b"]["value"] == 7.0e5


def test_windows_of_the_practice_profile():
    t = np.round(np.arange(0, 30001) * 1e-3, 9)
    ref = practice_profile(0.06, 0.16).at(t)
    w = derive_windows(t, ref, transient_duration=1.0, stroke=0.16)
    expect = [(0, 2, "steady"), (2, 3, "transient"), (3, 5, "steady"), (5, 6, "transient"), (6, 8, "steady"),
              (8, 9, "transient"), (9, 11, "steady"), (11, 12, "transient"), (12, 14, "steady"), (14, 15, "transient"),
              (15, 17, "steady"), (17, 18, "transient"), (18, 20, "steady"), (20, 30, "transient")]
    assert [x.kind for x in w] == [k for _, _, k in expect]
    # a change is seen at the first sample that differs: exact for the steps, one sample late for the sine
    assert np.allclose([(x.start, x.end) for x in w], [(a, b) for a, b, _ in expect], atol=1e-3 + 1e-9)
    assert w[1].name == "step +3.2 mm at 2.00 s" and w[-1].name.startswith("tracking")
    assert derive_windows(t, None, 1.0, 0.16)[0].kind == "steady"


def test_window_metrics_hand_case():
    t = np.arange(0.0, 4.0, 0.001)
    rec = 0.05 + 0.0 * t
    sim = rec.copy()
    sim[(t >= 2.0)] -= 0.0032  # model 3.2 mm low in the second half = 0.02 pu on a 160 mm stroke
    wins = [ErrorWindow("first", 0.0, 2.0, "steady"), ErrorWindow("second", 2.0, 4.0, "steady")]
    settings = MetricSettings(error_filter_cutoff=0.0)
    rows = window_metrics(t, {"position": rec}, {"position": sim}, {"position": 0.16}, wins, settings)
    first, second = rows
    assert first["max_error"] == 0.0 and first["pass"]
    assert second["mean_error"] == pytest.approx(0.02, rel=1e-9)  # recorded - simulated > 0
    assert second["max_error"] == pytest.approx(0.02, rel=1e-9)
    assert not second["pass"] and set(second["failed"]) == {"max_error", "mean_error", "mean_absolute_error"}
    assert second["limits"] == DEFAULT_LIMITS[("position", "steady")].as_dict()


def test_error_filter_keeps_dc_and_removes_noise():
    t = np.arange(0.0, 2.0, 0.001)
    assert np.allclose(filtered_error(t, np.full(t.size, 0.01), 20.0), 0.01)  # unit DC gain
    hf = np.sin(2 * np.pi * 400.0 * t)
    # 2nd-order Butterworth forward and backward: |H(400 Hz)|^2 = 1 / (1 + (400/20)^4) ~ 6e-6
    assert np.max(np.abs(filtered_error(t, hf, 20.0)[200:-200])) < 1e-4
    assert filtered_error(t, hf, 0.0) is hf or np.array_equal(filtered_error(t, hf, 0.0), hf)


def test_settings_file(tmp_path):
    f = tmp_path / "val.toml"
    f.write_text(
        """
[replay]
modes = ["plant_only"]
[locate]
k_on = 4
smoothing = "20 ms"
[metrics]
error_filter_cutoff = "10 Hz"
[limits.position.steady]
max_error = 0.004
mean_error = "none"
[[windows]]
name = "step"
start = "8 s"
end = "11 s"
kind = "transient"
""",
        encoding="utf-8",
    )
    s = load_settings(f)
    assert s.modes == ("plant_only",)
    assert s.locate.k_on == 4.0 and s.locate.smoothing == pytest.approx(0.02)
    assert s.metrics.error_filter_cutoff == 10.0
    lim = s.metrics.limits[("position", "steady")]
    assert lim.max_error == 0.004 and lim.mean_error is None
    assert lim.mean_absolute_error == DEFAULT_LIMITS[("position", "steady")].mean_absolute_error  # untouched
    assert s.metrics.windows[0] == ErrorWindow("step", 8.0, 11.0, "transient")


@pytest.mark.parametrize(
    "table, message",
    [
        ({"limts": {}}, "did you mean 'limits'"),
        ({"locate": {"k_onn": 3}}, "did you mean 'k_on'"),
        ({"limits": {"positon": {"steady": {"max_error": 0.1}}}}, "did you mean 'position'"),
        ({"limits": {"position": {"steady": {"max_error": -1}}}}, "limits.position.steady.max_error"),
        ({"limits": {"position": {"stedy": {"max_error": 1}}}}, "did you mean 'steady'"),
        ({"windows": [{"start": 5, "end": 2}]}, "start < end"),
        ({"windows": [{"start": 1, "end": 2, "kind": "fast"}]}, "kind 'fast'"),
        ({"replay": {"modes": ["open_loop"]}}, "replay.modes"),
        ({"metrics": {"error_filter_cutoff": "10 m"}}, "metrics.error_filter_cutoff"),
    ],
)
def test_bad_settings(table, message):
    with pytest.raises(InputError, match=message):
        settings_from_dict(table, "val.toml")


def test_command_line_overrides():
    t = apply_overrides({}, ["limits.position.steady.max_error=0.02", "locate.smoothing=20 ms", "replay.noise=none"])
    s = settings_from_dict(t)
    assert s.metrics.limits[("position", "steady")].max_error == 0.02
    assert s.locate.smoothing == pytest.approx(0.02) and s.noise == "none"
    with pytest.raises(InputError, match="KEY.PATH=VALUE"):
        apply_overrides({}, ["locate.k_on"])


def test_decimation_keeps_extremes():
    y = np.sin(np.linspace(0, 20, 100000))
    y[12345] = 5.0  # a spike must survive the decimation
    idx = decimation_indices(y, 3000)
    assert len(idx) <= 3000 and np.all(np.diff(idx) > 0)
    assert 12345 in idx and idx[0] == 0 and idx[-1] == y.size - 1
    assert len(decimation_indices(y[:500], 3000)) == 500

"""The scan along a lag's lumped valley (compliance.diagnosis.servo.lag_split) and how practice scoring keeps it apart."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from compliance.diagnosis.servo.candidates import effect_params
from compliance.diagnosis.servo.fit import FitResult
from compliance.diagnosis.scoring.practice_score import answer_in_si, main_parameter
from compliance.diagnosis.servo.lag_split import valley_point, split_scan

M = 100  # residuals per signal
SIGNALS = ("position", "pressure_a")


class _Valley:
    """A stand-in replay: chi-square per signal as a function of (tau, t_d), unit floors."""

    def __init__(self, chi2_of):
        self.chi2_of = chi2_of
        self.calls = []
        self.sims = 0  # replays run (FitContext.sims)
        self.model = SimpleNamespace(index=np.arange(M), size=M * len(SIGNALS), split=self._split)

    def _split(self, vec):
        return {s: vec[i * M:(i + 1) * M] for i, s in enumerate(SIGNALS)}

    def residual(self, params, values):
        p = {fp.name: v for fp, v in zip(params, values)}
        self.calls.append(p)
        self.sims += 1
        per = self.chi2_of(p["time_constant"], p["delay"]) / len(SIGNALS)
        return np.full(M * len(SIGNALS), np.sqrt(per / M)), object()


def _fit(ctx, tau, td):
    params = effect_params("sensor_lag")
    vec, _ = ctx.residual(params, [tau, td])
    parts = {s: float(r @ r) for s, r in ctx.model.split(vec).items()}
    return FitResult("sensor_lag", params, [tau, td], [0.0, 0.0], sum(parts.values()), parts, ctx.model.size)


def test_flat_valley_leaves_the_split_open_and_holds_the_total():
    """chi2 depends on the total lag only (plus 5 % wrinkles): every scanned split is as good, the
    interval spans the scan; the delay is re-solved to hold tau + t_d at the fitted 24 ms (and at +-4 %,
    the coarse profile of the total)."""
    ctx = _Valley(lambda tau, td: 200.0 * (1.0 + 1e5 * (tau + td - 0.024) ** 2) * (1.0 + 0.05 * np.sin(3e3 * tau)))
    fit = _fit(ctx, 0.02, 0.004)
    sp = split_scan(ctx, fit, "sensor_lag")
    totals = [p["time_constant"] + p["delay"] for p in ctx.calls[1:]]  # the fit first, then the scan
    assert all(0.024 * 0.96 - 1e-12 <= t <= 0.024 * 1.04 + 1e-12 for t in totals)
    assert 0.024 in [pytest.approx(t, abs=1e-12) for t in totals]  # the valley at the fitted total is scanned
    assert not sp["pinned"]
    assert sp["interval"][0] <= 0.015 <= sp["interval"][1]  # a split of 15 + 9 ms is not told apart
    assert sp["lumped"] == pytest.approx(0.024)
    assert sp["replays"] == len(ctx.calls) - 1  # every replay of the scan counted (the fit's own was before it)
    # the scan's points are independent: run by a caller's workers (here: in reverse order), the same scan
    again = split_scan(ctx, fit, "sensor_lag", along=lambda vs, lim: [valley_point(ctx, fit, "sensor_lag", v, lim)
                                                                      for v in vs[::-1]][::-1])
    assert again == sp


def test_sharp_valley_pins_the_split():
    """chi2 doubles 10 % away from the fitted time constant along the valley: the interval is the fit."""
    ctx = _Valley(lambda tau, td: 200.0 * (1.0 + 100.0 * ((tau - 0.02) / 0.02) ** 2))
    sp = split_scan(ctx, _fit(ctx, 0.02, 0.004), "sensor_lag")
    assert sp["pinned"]
    assert sp["interval"] == [0.02, 0.02]


def test_practice_scoring_keeps_an_open_split_apart_from_a_hit():
    """A 33 % error is no hit even when the open split interval holds the truth; answers per bar go to SI."""
    assert answer_in_si("kp_fric", 0.1) == pytest.approx(1e-6)
    d = SimpleNamespace(split={"parameter": "sensor_lag.time_constant", "interval": [0.0139, 0.0199], "pinned": False})
    params = {"tau_s": {"true": 0.015, "fitted": 0.0199, "error": 0.33}, "td_s": {"true": 0.008, "fitted": 0.0041, "error": 0.49}}
    m = main_parameter(d, ["sensor_lag"], params)
    assert m["parameter"] == "tau_s"
    assert not m["within_25"]
    assert m["interval_contains_truth"] and not m["split_pinned"]
    d.split["interval"] = [0.0178, 0.0249]
    assert not main_parameter(d, ["sensor_lag"], params)["interval_contains_truth"]


def test_a_pinned_split_is_bracketed_by_the_values_that_fit_worse():
    ctx = _Valley(lambda tau, td: 200.0 * (1.0 + 100.0 * ((tau - 0.02) / 0.02) ** 2))
    sp = split_scan(ctx, _fit(ctx, 0.02, 0.004), "sensor_lag")
    assert sp["bracket"] == [pytest.approx(0.018), pytest.approx(0.0224)]  # the scan's 0.9 and 1.12 x the fit


def test_trimmed_chi2_leaves_out_the_worst_fifth_of_the_segments():
    from compliance.diagnosis.servo.lag_split import trimmed_chi2

    segments = np.repeat(np.arange(10), 20)
    vec = np.ones(200)
    vec[segments == 3] = 10.0  # one segment with a slip the model makes and the bench did not
    assert float(vec @ vec) / vec.size == pytest.approx(10.9)
    assert trimmed_chi2(vec, segments) == pytest.approx(1.0)  # 8 of 10 segments kept: the slip is out


class _Segmented(_Valley):
    """Ten segments: nine say the split is tau = 17.5 ms, one (a stick-slip burst) pulls the pooled optimum to 20 ms."""

    def __init__(self):
        super().__init__(lambda tau, td: 0.0)
        self.setup = SimpleNamespace(resets=np.arange(0, M, M // 10))

    def residual(self, params, values):
        p = {fp.name: v for fp, v in zip(params, values)}
        self.calls.append(p)
        tau = p["time_constant"]
        quiet = 0.5 + 1e4 * (tau - 0.0175) ** 2  # chi2 per residual in the nine segments that agree
        burst = 10.0 + 1.125e5 * (tau - 0.022) ** 2  # ... and in the burst one: d(pooled)/d tau = 0 at 20 ms
        per = np.full(M, quiet)
        per[:M // 10] = burst
        return np.tile(np.sqrt(per), len(SIGNALS)), object()


def test_the_segments_estimate_an_undetermined_split_the_pooled_fit_misplaces():
    ctx = _Segmented()
    fit = _fit(ctx, 0.02, 0.004)
    sp = split_scan(ctx, fit, "sensor_lag")
    assert not sp["pinned"]
    est = sp["estimate"]
    assert est is not None and est["value"] == pytest.approx(0.018)  # the scan's 0.9 x the fit, nearest to 17.5 ms
    assert est["trimmed"] < est["trimmed_fit"]
    assert sum(est["values"]) == pytest.approx(0.024, rel=0.05)  # the total lag is held

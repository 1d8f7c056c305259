"""An effect set's effects each beat the instrumentation explanation of the same misfit (servo.effect_sets.prune), fits
not refined where they cannot matter (servo.fit.screen_level), and no parameter set replayed twice (FitContext memo).

The selection rules are checked on constructed fit results (the chi-squares a diagnosis would produce), so
each test runs in milliseconds; the end-to-end proof is the field practice recording with an external leak,
a position-dependent load and a -1 % pressure_b gain (docs/diagnosis.md, practice set 3).
"""

from __future__ import annotations

import math

import pytest

from compliance.diagnosis.servo import fit as fit_module
from compliance.diagnosis.servo.candidates import effect_params
from compliance.diagnosis.servo import recalibration
from compliance.diagnosis.servo.candidates import base_params
from compliance.diagnosis.servo.fit import SCREEN_SHARE, SINGLE_SCREEN_SHARE, FitContext, FitResult, screen_level
from compliance.diagnosis.servo.instrument_candidates import instrument_candidates
from compliance.diagnosis.servo.effect_sets import full_name, prune, reduced_sets
from compliance.diagnosis.verdicts.candidate_set import CandidateSet
from compliance.model.config import load_plant

N = 10000  # residuals


def _gain() -> FitResult:
    """The pressure-gain finding fitted alone: 0.99 on pressure_b removes 30 % of the nominal excess."""
    cand = next(c for c in instrument_candidates(("position", "pressure_b", "valve_command"), True)
                if c.name == "instrument:pressure_gain")
    return FitResult(cand.name, cand.params, [0.99], [0.001], 7.0e5, {}, N)


def _set(effects, values=None, chi2=14000.0) -> FitResult:
    params = tuple(fp for e in effects for fp in effect_params(e))
    return FitResult("+".join(effects), params, values or [fp.nominal or 1.0 for fp in params], [], chi2, {}, N)


def _runner(fits: dict, chi2: dict, calls: list):
    def run(tasks):
        calls.append([t[0] for t in tasks])
        for name, params, start in tasks:
            fits[name] = FitResult(name, params, list(start), [], chi2[name], {}, N)
    return run


def test_an_effect_a_later_one_made_redundant_gives_its_place_to_the_instrumentation_finding():
    """supply_droop won alone, the load and the leak were added after it; with the pressure gain on top the
    set without it fits as well, so it goes; each of the two left beats its removal, so they stay."""
    fits = {"nominal": FitResult("nominal", (), [], [], 1.0e6, {}, N), "instrument:pressure_gain": _gain()}
    winner = _set(["supply_droop", "position_dependent_load", "external_leakage"])
    fits[winner.name] = winner
    g = "+instrument:pressure_gain"
    chi2 = {"position_dependent_load+external_leakage" + g: 13900.0, "supply_droop+external_leakage" + g: 5e5,
            "supply_droop+position_dependent_load" + g: 4e5, "external_leakage" + g: 6e5, "position_dependent_load" + g: 5e5}
    calls = []
    best, log = prune(fits, winner.name, N, _runner(fits, chi2, calls))
    assert best == "position_dependent_load+external_leakage" + g
    assert [r["kept"] for r in log] == [True, False]
    assert "supply_droop does not beat" in log[0]["why"]
    assert len(calls) == 2 and len(calls[0]) == 3 and len(calls[1]) == 2
    # the finding starts at its own fit, the effects kept at the set's optimum
    start = fits[best].values
    assert start[-1] == pytest.approx(0.99) and len(start) == 3


def test_a_set_whose_effects_each_beat_their_removal_stays():
    fits = {"nominal": FitResult("nominal", (), [], [], 1.0e6, {}, N)}  # no instrumentation finding beats the nominal
    winner = _set(["heat_transfer", "internal_leakage"], chi2=12000.0)
    fits[winner.name] = winner
    calls = []
    best, log = prune(fits, winner.name, N, _runner(fits, {"heat_transfer": 3e5, "internal_leakage": 2e5}, calls))
    assert best == winner.name and log[0]["kept"] is False
    assert calls == [["internal_leakage", "heat_transfer"]]  # plain backward elimination: nothing on top


def test_a_single_effect_is_not_pruned_and_no_refit_is_repeated():
    fits = {"nominal": FitResult("nominal", (), [], [], 1.0e6, {}, N), "heat_transfer": _set(["heat_transfer"])}
    assert prune(fits, "heat_transfer", N, lambda tasks: pytest.fail("no refit for one effect")) == ("heat_transfer", [])


def test_reduced_set_names_keep_the_instrument_and_base_terms_in_order():
    cur = _set(["supply_droop", "external_leakage"])
    names = [name for name, _, _ in reduced_sets(cur, _gain())]
    assert names == ["external_leakage+instrument:pressure_gain", "supply_droop+instrument:pressure_gain"]
    params = effect_params("external_leakage") + _gain().params
    assert full_name(["external_leakage"], params) == "external_leakage+instrument:pressure_gain"


def test_a_finding_on_top_does_not_make_another_physics():
    cs = CandidateSet.parse
    assert cs("a+b").same_physics(cs("a+b+instrument:pressure_gain"))
    assert cs("a+b+c").nested(cs("a+b+instrument:pressure_gain"))  # the reduced set is no rival of the set it came from
    assert not cs("a+c").nested(cs("b+instrument:pressure_gain"))


def test_the_screen_level_asks_two_percent_of_the_nominal_excess():
    assert screen_level(1.0e6, N) == pytest.approx(1.0e6 - SCREEN_SHARE * (1.0e6 - N))
    assert screen_level(0.9 * N, N) == pytest.approx(0.9 * N)  # no excess: nothing below the nominal is asked


def test_a_single_effect_is_refined_only_when_its_grid_removes_a_tenth_of_the_excess():
    # below select.MIN_GAIN = 25 % with room for what a refinement adds (+0.13 at most on the practice sets)
    assert SINGLE_SCREEN_SHARE == pytest.approx(0.10)
    assert screen_level(3.0 * N, N, SINGLE_SCREEN_SHARE) == pytest.approx(3.0 * N - 0.2 * N)


class _Model:
    size = N


class _Ctx:
    model = _Model()
    sims = 0


def _recalibrate(monkeypatch, scans: dict) -> list:
    """Refined parameter keys of one recalibration whose scans reach ``scans`` (key -> chi-square; nothing joins)."""
    refined = []
    monkeypatch.setattr(recalibration, "least_squares_fit", lambda *a, **k: FitResult("base", (), [], [], 3.0 * N, {}, N))
    monkeypatch.setattr(recalibration, "_scan", lambda ctx, trials: {fp.key: (scans.get(fp.key, 3.0 * N), fp.nominal, fp)
                                                                    for fp, _, _ in trials})

    def refine(ctx, chosen, values, fp, start):
        refined.append(fp.key)
        return scans.get(fp.key, 3.0 * N), start

    monkeypatch.setattr(recalibration, "_refine_1d", refine)
    recalibration.forward_select_base(_Ctx(), base_params(load_plant("plant-a")), penalty=100.0)
    return refined


def test_a_recalibration_refines_only_parameters_whose_scan_could_join(monkeypatch):
    # joining needs JOIN_GAIN x the excess 2 N = 0.5 N; a scan must show a quarter of that (0.125 N) to be refined
    refined = _recalibrate(monkeypatch, {"friction.level": 2.8 * N, "cylinder.dead_volume": 2.95 * N})
    assert refined == ["friction.level"]
    assert _recalibrate(monkeypatch, {"friction.level": 2.9 * N}) == []


def test_a_parameter_set_is_replayed_once(monkeypatch):
    calls = []

    def fake(model, cfg, setup, limit=math.inf):
        calls.append(cfg)
        return [len(calls)], None, False

    monkeypatch.setattr(fit_module, "evaluate", fake)
    ctx = FitContext(load_plant("plant-a"), None, None)
    params = effect_params("heat_transfer")
    first = ctx.residual(params, [9.0])
    assert ctx.residual(params, [9.0 * (1 + 1e-14)]) is first  # a round trip through the unit cube
    assert ctx.residual(params, [9.1])[0] == [2]
    assert ctx.sims == 2 and len(calls) == 2
    for k in range(fit_module.MEMO + 1):
        ctx.residual(params, [100.0 + k])
    assert len(ctx.memo) == fit_module.MEMO
    assert ctx.sims == 2 + fit_module.MEMO + 1  # the values 100 + k are all new

"""Design the test that tells two explanations apart.

When two explanations fit a recording equally well (``servo.selection.ambiguity_set``), the recording
cannot decide between them; another test can. Each explanation, with its fitted values, is
simulated (noise-free, closed loop, same controller) over a small set of tests the bench can
run: the same test again (the reference: the two predictions should agree there), another
supply pressure, another load, another stroke position, a slow ramp and a long hold. The
recommended test is the one whose predicted signals differ most relative to the recording's
noise floors (largest normalised RMS difference over the measured signals; Box & Hill 1967:
choose the experiment that maximises the expected divergence of the rival models' predictions).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from compliance.validation.replay_conditions import load_at_start
from compliance.errors import InputError, SimulationError
from compliance.recordings.synth import practice_profile
from compliance.simulation import Scenario
from compliance.plants import simulate
from compliance.simulation.profiles import Profile

SUPPLY_FACTOR = 0.7  # another supply pressure: 70 % of the recording's (a regulator setting any bench has)
TEST_DURATION = 17.0  # s; the practice steps without the sinusoid (each candidate test)
RAMP_FRACTION = 0.15  # slow ramp: 15 % of the stroke over RAMP_SECONDS
RAMP_SECONDS = 12.0
HOLD_STEP = 0.10  # hold test: a 10 % step, then held for the rest of the test
TRACE_STEP = 0.02  # s; resolution of the predicted traces handed to the report
SIGNALS = ("position", "pressure_a", "pressure_b", "valve_command", "supply_pressure")


@dataclass(frozen=True)
class TestPlan:
    """One candidate discriminating test."""

    key: str
    words: str
    x0: float
    load: float
    supply_factor: float
    reference: Profile
    duration: float


def _other_position(x0: float, stroke: float) -> float:
    """The stroke position farthest from ``x0`` among a quarter and three quarters of the stroke."""
    return 0.25 * stroke if x0 > 0.5 * stroke else 0.6 * stroke


def _other_load(load: float) -> float:
    """A clearly different load: a quarter of a large load, or a large load where it was small."""
    return 0.25 * load if abs(load) > 4000.0 else (load + 6000.0 if load >= 0 else load - 6000.0)


def candidate_tests(x0: float, load: float, stroke: float) -> list[TestPlan]:
    """The tests the diagnosis knows how to propose, around the recording's operating point."""
    steps = practice_profile(x0, stroke, TEST_DURATION, sine=False)
    xo = _other_position(x0, stroke)
    up = 1.0 if x0 + RAMP_FRACTION * stroke <= stroke else -1.0
    ramp = Profile(np.array([0.0, 2.0, 2.0 + RAMP_SECONDS, TEST_DURATION]),
                   np.array([x0, x0, x0 + up * RAMP_FRACTION * stroke, x0 + up * RAMP_FRACTION * stroke]))
    hold = Profile(np.array([0.0, 1.0, 1.0, TEST_DURATION]), np.array([x0, x0, x0 + up * HOLD_STEP * stroke,
                                                                          x0 + up * HOLD_STEP * stroke]))
    return [
        TestPlan("same", "the same test again", x0, load, 1.0, steps, TEST_DURATION),
        TestPlan("supply", f"the same steps at {100*SUPPLY_FACTOR:.0f} % of the supply pressure", x0, load, SUPPLY_FACTOR,
                 steps, TEST_DURATION),
        TestPlan("load", f"the same steps under a {_other_load(load)/1e3:.1f} kN closing load", x0, _other_load(load), 1.0,
                 steps, TEST_DURATION),
        TestPlan("position", f"the same steps from {xo*1e3:.0f} mm", xo, load, 1.0,
                 practice_profile(xo, stroke, TEST_DURATION, sine=False), TEST_DURATION),
        TestPlan("ramp", f"a slow ramp of {RAMP_FRACTION*stroke*1e3:.0f} mm over {RAMP_SECONDS:.0f} s", x0, load, 1.0, ramp,
                 TEST_DURATION),
        TestPlan("hold", f"a {HOLD_STEP*stroke*1e3:.0f} mm step held for {TEST_DURATION - 1:.0f} s", x0, load, 1.0, hold,
                 TEST_DURATION),
    ]


def _predict(cfg, plan: TestPlan):
    if plan.supply_factor != 1.0:
        cfg = cfg.replace(params={"air.supply_pressure": cfg.p("air.supply_pressure") * plan.supply_factor})
    try:
        df = simulate(cfg, Scenario(duration=plan.duration, initial_position=plan.x0, reference=plan.reference,
                                    load=load_at_start(cfg, plan.load, plan.x0), noise=None))
    except (SimulationError, InputError):
        return None
    return df


def design_test(cfg_a, cfg_b, floors: dict, *, x0: float, load: float, names=("A", "B")) -> dict:
    """Simulate two fitted explanations over the candidate tests and recommend the most telling one.

    Parameters
    ----------
    cfg_a, cfg_b : PlantConfig
        The two explanations, fitted (recording overrides applied).
    floors : dict
        Signal -> noise floor of the recording [SI]; the predicted differences are divided by it.
    x0, load : float
        The recording's operating point [m], [N].
    names : tuple of str
        Names of the two explanations (for the output).

    Returns
    -------
    dict
        ``explanations`` (the two names), ``tests`` (per test: key, words, ``difference``: the
        largest normalised RMS difference, ``signal`` where it is, ``per_signal``), ``recommended``
        (the best test's entry plus ``traces``: time and both predictions of each signal) and
        ``separates`` (True when the recommended test's difference exceeds 3 noise floors).
    """
    stroke = cfg_a.p("cylinder.stroke")
    rows, best, best_pred = [], None, None
    for plan in candidate_tests(x0, load, stroke):
        pa, pb = _predict(cfg_a, plan), _predict(cfg_b, plan)
        if pa is None or pb is None:
            rows.append({"key": plan.key, "test": plan.words, "difference": None, "signal": None, "per_signal": {}})
            continue
        per = {}
        for s in SIGNALS:
            if s in floors and s in pa and floors[s] > 0:
                per[s] = float(np.sqrt(np.mean((pa[s].to_numpy() - pb[s].to_numpy()) ** 2)) / floors[s])
        sig = max(per, key=per.get) if per else None
        row = {"key": plan.key, "test": plan.words, "difference": per.get(sig) if sig else None, "signal": sig,
               "per_signal": per}
        rows.append(row)
        if plan.key != "same" and sig and (best is None or row["difference"] > best["difference"]):
            best, best_pred = row, (pa, pb)
    out = {"explanations": list(names), "tests": rows, "recommended": None, "separates": False}
    if best is not None:
        pa, pb = best_pred
        t = pa["time"].to_numpy()
        idx = np.arange(0, t.size, max(1, int(round(TRACE_STEP / max(t[1] - t[0], 1e-9)))))
        traces = {"time": t[idx].tolist()}
        for s in best["per_signal"]:
            traces[s] = {names[0]: pa[s].to_numpy()[idx].tolist(), names[1]: pb[s].to_numpy()[idx].tolist()}
        out["recommended"] = dict(best, traces=traces)
        out["separates"] = bool(best["difference"] > 3.0)
    return out


def suggestion_lines(suggestion: dict | None) -> list[str]:
    """The suggested test in plain lines (``govcheck diagnose --suggest-test``)."""
    if not suggestion:
        return ["suggested test: none (a single explanation, or nothing to tell apart)"]
    a, b = suggestion["explanations"]
    lines = [f"suggested test to tell {a} from {b}:"]
    rec = suggestion.get("recommended")
    if rec is None:
        return lines + ["  no candidate test could be simulated for both explanations"]
    lines.append(f"  {rec['test']}: predictions differ by {rec['difference']:.1f} x the noise floor on {rec['signal']}"
                 + ("" if suggestion.get("separates") else " (may not be enough to separate them)"))
    lines.append("  all candidate tests (largest normalised RMS difference):")
    for row in suggestion["tests"]:
        diff = "not simulated" if row["difference"] is None else f"{row['difference']:.2f} on {row['signal']}"
        lines.append(f"    {row['test']:48s} {diff}")
    lines.append("  once recorded: govcheck diagnose CONFIG THIS_RECORDING NEW_RECORDING (both at once: shared physics, "
                 "each with its own conditions)")
    return lines


__all__ = ["design_test", "candidate_tests", "suggestion_lines", "TestPlan"]

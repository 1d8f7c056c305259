"""Paper comparison: run the tests of seed 000 section 5 and set the simulated figures beside the paper's.

The table is ``reference-plant.md`` "Results the model must be compared with". Metric
definitions (stated in the output and docs/physics.md):

- settling time: from the step instant to the last time the position is outside a band of
  +/- 5 % of the actual change around the settled position (settled = mean of the last
  0.5 s before the next step); the paper does not define its band;
- steady error: |set-point - settled position| (same window);
- full-stroke times t_a / t_f: 25 % -> 75 % of the stroke at full command with the
  flow-control valves installed, extrapolated to 100 % (the straight part of the trace);
- maximum speed: peak |dx/dt| over the full-stroke runs (20 ms central difference).

A figure off by more than 35 % (settling) or 0.3 mm (steady error) is flagged and the
assumed parameters are perturbed by +/-20 % to show which one drives it: nothing is tuned.
The paper's overall figure (position errors of 0.5-0.8 % of stroke over the 1, 2, 5 and 10 %
steps and the 8 mm sinusoid, section 6) is a measured range: a simulated figure outside it is
flagged. :data:`BEARS_ON` names the govcheck metrics each figure is evidence for.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from compliance.model.config import PlantConfig
from compliance.model.pid_controller import stall_error
from compliance.papers.plant_a_fig8 import fig8, format_fig8
from compliance.metrics import find_steps, speed_extremes, step_response, stroke_time
from compliance.simulation.scenario import stroke_start_pressures
from compliance.simulation.profiles import Profile, steps
from compliance.simulation import Scenario
from compliance.plants import simulate

SETTLING_BAND = 0.05  # fraction of the actual change
SETTLING_TOLERANCE = 0.35  # relative
STEADY_TOLERANCE = 0.3e-3  # m
# the paper's own scatter per metric: (kind, width); a row outside it is flagged
TOLERANCES = {
    "settling time": ("rel", SETTLING_TOLERANCE),
    "steady error": ("abs", STEADY_TOLERANCE),
    "opening time t_a": ("rel", 0.05),
    "closing time t_f": ("rel", 0.05),
    "max speed": ("rel", 0.30),
}
# test conditions the lost figures leave open (choices; the calibration picks, docs/calibration.md)
FIG9_SEQUENCES = {"alternating": "2%@4s,-2%@9s,2%@14s", "staircase": "2%@4s,2%@9s,2%@14s"}
# full strokes from the end stop by default, as the full_stroke procedure of `check` starts them
DEFAULT_CONDITIONS = {"fig9_sequence": "alternating", "full_stroke_start": "end_stop"}
STROKE_TEST = "speed-governor set-up (5.7 kN)"  # the full strokes of section 5.2
SENSITIVITY_STEP = 0.2  # relative perturbation of assumed parameters
# the paper's overall position errors, section 6: 0.5-0.8 % of stroke over the step and sinusoid tests
OVERALL_ERROR_RANGE = (0.005, 0.008)  # fraction of stroke
# the govcheck metrics (compliance.metrics.catalogue) each measured figure is evidence for: a verdict on one of
# them rests on what this figure measures (govcheck's reading of the paper's definitions, module docstring)
BEARS_ON = {
    "settling time": ("settling_time", "time_constant", "dead_time"),
    "steady error": ("max_positioning_error", "dead_band"),
    "opening time t_a": ("opening_time", "stroke_speed"),
    "closing time t_f": ("closing_time", "stroke_speed"),
    "max speed": ("max_speed", "max_opening_speed", "max_closing_speed"),
    "max tracking error": ("tracking_max_error",),
    "max steady error": ("max_positioning_error",),
}
SENSITIVITY_PARAMS = (
    "friction.static_force",
    "friction.coulomb_force",
    "friction.stribeck_velocity",
    "friction.viscous_coefficient",
    "friction.bristle_stiffness",
    "valve.saturation_voltage",
    "controller.filter_cutoff",
)


@dataclass(frozen=True)
class StepCase:
    """A closed-loop step test of the paper."""

    test: str
    x0: float  # m
    load: float  # N, > 0 closes
    kd: float  # V*s/m
    spec: str  # step sequence
    duration: float  # s
    flow_control: bool
    paper: dict  # step index -> (settling [s] or None, steady error [m] or None)
    note: str = ""


CASES = (
    StepCase("fig. 9, steps at 4 s and 9 s", 0.136, 11400.0, 6.0, "2%@4s,-2%@9s,2%@14s", 19.0, False,
             {0: (1.18, 0.32e-3), 1: (1.18, 0.32e-3)}, "sequence assumed up/down/up (fig. 9 is lost)"),
    StepCase("fig. 9, step at 14 s", 0.136, 11400.0, 6.0, "2%@4s,-2%@9s,2%@14s", 19.0, False, {2: (0.55, None)}),
    StepCase("fig. 10, positive step", 0.128, 11200.0, 20.0, "5%@1s,-5%@4s", 7.0, True, {0: (0.33, 0.24e-3)},
             "flow-control valves installed (section 5.2)"),
    StepCase("fig. 10, negative step", 0.128, 11200.0, 20.0, "5%@1s,-5%@4s", 7.0, True, {1: (0.56, 0.24e-3)}),
    StepCase("fig. 11 (+2.3 kN closing)", 0.016, 2300.0, 20.0, "5%@1s,-5%@4s", 7.0, True, {0: (1.4, 0.8e-3)}),
    StepCase("fig. 12 (-2.3 kN opening)", 0.016, -2300.0, 20.0, "5%@1s,-5%@4s", 7.0, True, {0: (0.55, 0.27e-3)},
             "paper: 0.5-0.6 s"),
)


@dataclass
class Row:
    """One line of the comparison."""

    test: str
    metric: str
    simulated: float | None
    paper: float | None
    unit: str
    flagged: bool = False
    driver: str = ""
    note: str = ""
    paper_range: tuple | None = None  # a figure the paper gives as a range (low, high), in the row's SI unit


@dataclass
class Comparison:
    """The whole paper comparison."""

    rows: list[Row] = field(default_factory=list)
    stall_error: float = 0.0
    notes: list[str] = field(default_factory=list)
    fig8: list = field(default_factory=list)  # plant_a_fig8.Fig8Step, with and without compensation


def _step_metrics(cfg: PlantConfig, case: StepCase, memo: dict | None = None):
    """Step responses of one case; ``memo`` (a dict kept for one configuration) reuses a run."""
    key = (case.x0, case.load, case.kd, case.spec, case.duration, case.flow_control)
    if memo is not None and key in memo:
        return memo[key]
    c = cfg.replace(params={"controller.kd": case.kd}, sources={"controller.kd": cfg.sources.get("controller.kd", "user")})
    stroke = c.p("cylinder.stroke")
    ref = steps(case.spec, case.x0, stroke)
    df = simulate(c, Scenario(duration=case.duration, initial_position=case.x0, reference=ref,
                              load=case.load, flow_control=case.flow_control))
    t = df.time.to_numpy()
    events = find_steps(t, df.reference.to_numpy())
    out = [step_response(t, df.position_true.to_numpy(), ev, settling_band=SETTLING_BAND) for ev in events]
    if memo is not None:
        memo[key] = out
    return out


def _case_rows(cfg: PlantConfig, case: StepCase, memo: dict | None = None) -> list[Row]:
    metrics = _step_metrics(cfg, case, memo)
    rows = []
    for idx, (p_settle, p_err) in case.paper.items():
        m = metrics[idx]
        label = f"{case.test} (step {idx + 1})" if len(case.paper) > 1 else case.test
        rows.append(Row(label, "settling time", m.settling_time, p_settle, "s", note=case.note))
        rows.append(Row(label, "steady error", m.steady_state_error, p_err, "mm"))
    return rows


def case_test(row_test: str) -> str:
    """The test (``StepCase.test``, or ``STROKE_TEST``) a row belongs to (a multi-step case adds " (step k)")."""
    for c in CASES:
        if row_test == c.test or row_test.startswith(c.test + " (step"):
            return c.test
    return row_test


def scaled_miss(row: Row) -> float | None:
    """(simulated - paper) in units of the paper's scatter for this metric (None: not compared)."""
    if row.paper is None or row.metric not in TOLERANCES:
        return None
    if row.simulated is None:
        return float("inf")
    kind, width = TOLERANCES[row.metric]
    return (row.simulated - row.paper) / (width * abs(row.paper) if kind == "rel" else width)


def agreement(row: Row) -> str | None:
    """``"agrees"`` (inside the paper's scatter or measured range), ``"contradicts"`` or None (no measured figure)."""
    if row.paper_range is not None:
        return "agrees" if row.simulated is not None and row.paper_range[0] <= row.simulated <= row.paper_range[1] \
            else "contradicts"
    r = scaled_miss(row)
    if r is None:
        return None
    return "agrees" if abs(r) <= 1.0 else "contradicts"


def _flag(row: Row) -> bool:
    return agreement(row) == "contradicts"


def conditions_of(cfg: PlantConfig) -> dict:
    """Test conditions recorded in a calibrated configuration's provenance (defaults otherwise)."""
    out = dict(DEFAULT_CONDITIONS)
    for k in out:
        v = cfg.provenance.get(f"condition_{k}")
        if v:
            out[k] = v.split()[0]
    return out


def cases(conditions: dict | None = None) -> tuple[StepCase, ...]:
    """The paper's step tests under the given test conditions (fig. 9's sequence shape)."""
    cond = dict(DEFAULT_CONDITIONS, **(conditions or {}))
    spec = FIG9_SEQUENCES[cond["fig9_sequence"]]
    out = []
    for c in CASES:
        if c.test.startswith("fig. 9"):
            note = f"sequence {cond['fig9_sequence']} (fig. 9 is lost)" if c.note else ""
            c = StepCase(c.test, c.x0, c.load, c.kd, spec, c.duration, c.flow_control, c.paper, note)
        out.append(c)
    return tuple(out)


def _metric_of(cfg: PlantConfig, case: StepCase, idx: int, metric: str):
    m = _step_metrics(cfg, case)[idx]
    return m.settling_time if metric == "settling time" else m.steady_state_error


def _driver(cfg: PlantConfig, case: StepCase, idx: int, row: Row) -> str:
    """Which assumed parameter, perturbed by +/-20 %, moves the figure most towards the paper."""
    base = row.simulated
    best = None
    for key in SENSITIVITY_PARAMS:
        if cfg.sources.get(key) != "assumed":
            continue
        for sign in (+1, -1):
            val = cfg.p(key) * (1 + sign * SENSITIVITY_STEP)
            try:
                got = _metric_of(cfg.replace(params={key: val}, sources={key: "assumed"}), case, idx, row.metric)
            except Exception:  # a perturbed variant that fails to settle says nothing useful here
                continue
            if got is None or base is None:
                continue
            gain = abs(base - row.paper) - abs(got - row.paper)
            if best is None or gain > best[0]:
                best = (gain, key, sign, got)
    if best is None or best[0] < 0.1 * abs(base - row.paper):
        if row.metric == "steady error" and base is not None and base >= 0.9 * stall_error(cfg):
            return (f"no assumed parameter moves it by +/-20 %: the valve shuts inside the stall band "
                    f"{stall_error(cfg) * 1e3:.2f} mm set by the paper's lc and K_P (see note)")
        return "no assumed parameter moves it meaningfully towards the paper by +/-20 %"
    scale = 1e3 if row.unit == "mm" else 1.0
    return (f"{best[1]} {'+' if best[2] > 0 else '-'}{SENSITIVITY_STEP:.0%} moves it to "
            f"{best[3] * scale:.3g} {row.unit}")


def full_stroke(cfg: PlantConfig, load: float = 5700.0, start: str = "balanced") -> dict:
    """Opening/closing times and peak speed at full command through the flow-control valves.

    ``start``: "balanced" starts at rest with the pressures balancing the load about their mean;
    "end_stop" starts where the previous stroke left the servo, the side that drove it there at
    supply pressure and the other exhausted to atmosphere (the paper does not say which).
    """
    stroke = cfg.p("cylinder.stroke")
    out = {}
    for name, direction in (("opening", +1), ("closing", -1)):
        x0 = 0.0 if direction > 0 else stroke
        u = cfg.p("valve.centre_voltage") + direction * cfg.p("valve.command_limit")
        cmd = Profile(np.array([0.0, 0.2, 0.2]), np.array([cfg.p("valve.centre_voltage")] * 2 + [u]))
        pressures = stroke_start_pressures(cfg, name, "rest" if start == "balanced" else start)
        df = simulate(cfg, Scenario(duration=12.0, initial_position=x0, command=cmd, load=load, flow_control=True,
                                    initial_pressures=pressures))
        t = df.time.to_numpy()
        x = df.position_true.to_numpy()
        out[name] = stroke_time(t, x, stroke, name)[0]
        out[f"{name}_speed"] = speed_extremes(t, x)[0]
    return out


def figure_rows(cfg: PlantConfig, conditions: dict | None = None, memo: dict | None = None,
                tests: frozenset | None = None) -> list[tuple[StepCase | None, int, Row]]:
    """The paper's figures (figs. 9-12, section 5.2) simulated: (case, step index, row), flags set.

    ``memo``: a dict kept for one configuration, so that several condition sets share the runs.
    ``tests``: only the rows of these tests (``Row.test`` names; the others are not simulated).
    """
    cond = dict(DEFAULT_CONDITIONS, **(conditions or {}))
    memo = {} if memo is None else memo
    out = []
    for case in cases(cond):
        if tests is not None and case.test not in tests:
            continue
        rows = _case_rows(cfg, case, memo)
        idxs = [i for i in case.paper for _ in (0, 1)]
        out.extend((case, idx, row) for idx, row in zip(idxs, rows))
    if tests is None or STROKE_TEST in tests:
        key = ("full_stroke", cond["full_stroke_start"])
        if key not in memo:
            memo[key] = full_stroke(cfg, start=cond["full_stroke_start"])
        fs = memo[key]
        for name, k in (("opening time t_a", "opening"), ("closing time t_f", "closing")):
            out.append((None, 0, Row(STROKE_TEST, name, fs[k], 5.0, "s")))
        vmax = max(fs["opening_speed"], fs["closing_speed"])
        out.append((None, 0, Row(STROKE_TEST, "max speed", vmax, 0.09, "m/s",
                                 note=f"full strokes start {cond['full_stroke_start']}")))
    for _, _, row in out:
        row.flagged = _flag(row)
    return out


def compare(cfg: PlantConfig, explain: bool = True, conditions: dict | None = None) -> Comparison:
    """Run every test of the paper table and build the comparison (see module docstring)."""
    comp = Comparison(stall_error=stall_error(cfg))
    cond = conditions_of(cfg) if conditions is None else conditions
    for case, idx, row in figure_rows(cfg, cond):
        if row.flagged and explain and case is not None:
            row.driver = _driver(cfg, case, idx, row)
        elif row.flagged and row.metric == "max speed":
            row.driver = ("peak speed comes from the first instants, when the exhaust side still holds its "
                          "initial pressure; the meter-out throttle model (series ISO 6358 conductance, no "
                          "throttle check valve dynamics) and the test's starting pressures set it")
        comp.rows.append(row)
    comp.rows.extend(_overall_rows(cfg))
    comp.fig8 = fig8(cfg)
    comp.notes.append(
        f"With lc = {cfg.p('controller.compensation_width'):.2f} V and K_P = {cfg.p('controller.kp'):.0f} V/m the "
        f"compensated valve stays shut once |e| < {comp.stall_error * 1e3:.2f} mm: an ideal dead zone leaves steady "
        f"errors up to that value, and stick-slip can end anywhere inside it. The paper measured 0.24-0.32 mm (up to "
        f"0.8 mm): flow through the real valve near its null, or a narrower lc, closes that gap (effect valve_null_flow; docs/calibration.md)."
    )
    return comp


def _overall_rows(cfg: PlantConfig) -> list[Row]:
    """The sinusoid (no paper figure) and the 1/2/5/10 % step campaign (paper: errors 0.5-0.8 % of stroke)."""
    from compliance.simulation.profiles import sine

    stroke = cfg.p("cylinder.stroke")
    x0, load = 0.08, 5700.0
    prof = sine(8e-3, 0.05, x0, start=1.0, duration=40.0)
    df = simulate(cfg, Scenario(duration=41.0, initial_position=x0, reference=prof, load=load))
    err = np.abs(df.reference.to_numpy() - df.position_true.to_numpy())[1000:]
    lo, hi = (f * stroke for f in OVERALL_ERROR_RANGE)
    rows = [Row("sinusoid 8 mm at pi/10 rad/s (80 mm, 5.7 kN)", "max tracking error", float(err.max()), hi, "mm",
                note="paper: position errors 0.5-0.8 % of stroke over its step and sinusoid tests", paper_range=(lo, hi))]
    worst = 0.0
    for pct in (1, 2, 5, 10):
        case = StepCase("", x0, load, cfg.p("controller.kd"), f"{pct}%@1s,-{pct}%@4s", 7.0, False, {})
        for m in _step_metrics(cfg, case):
            worst = max(worst, m.steady_state_error)
    r = Row("1, 2, 5, 10 % steps up and down (80 mm, 5.7 kN)", "max steady error", 100 * worst / stroke, 0.8, "% stroke",
            paper_range=tuple(100 * f for f in OVERALL_ERROR_RANGE))
    r.note = "paper: 0.5-0.8 % of stroke"
    rows.append(r)
    for row in rows:
        row.flagged = _flag(row)
    return rows


def format_table(comp: Comparison) -> str:
    """Plain-text table of the comparison with definitions and flags."""
    lines = [
        "Paper comparison, seed 000 section 5 (plant A)",
        f"  settling time: from the step to the last exit from +/-{SETTLING_BAND:.0%} of the actual change around the settled position",
        "  steady error: |set-point - mean position over the last 0.5 s before the next step|",
        "  t_a / t_f: 25 % -> 75 % of stroke at full command with 2V2/2V3 installed, extrapolated to 100 %",
        f"  flagged (!): settling off by > {SETTLING_TOLERANCE:.0%}, steady error off by > {STEADY_TOLERANCE * 1e3:.1f} mm,",
        "  stroke times within 5 %, peak speed within 30 %, overall errors outside the paper's 0.5-0.8 % of stroke",
        "",
        f"{'test':42s} {'metric':18s} {'simulated':>10s} {'paper':>9s}  ",
    ]
    for r in comp.rows:
        scale = 1e3 if r.unit == "mm" else 1.0
        sim = "-" if r.simulated is None else f"{r.simulated * scale:.3g}"
        pap = "-" if r.paper is None else f"{r.paper * scale:.3g}"
        if r.paper_range is not None:
            pap = "-".join(f"{v * scale:.3g}" for v in r.paper_range)
        flag = "!" if r.flagged else " "
        lines.append(f"{r.test:42s} {r.metric:18s} {sim:>10s} {pap:>9s} {r.unit:4s}{flag}")
        if r.flagged and r.driver:
            lines.append(f"{'':42s}   -> {r.driver}")
    lines.append("")
    if comp.fig8:
        lines += [format_fig8(comp.fig8), ""]
    lines.extend("Note: " + n for n in comp.notes)
    return "\n".join(lines)

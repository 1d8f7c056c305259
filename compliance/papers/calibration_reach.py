"""What would bring each figure the calibration leaves outside the paper's scatter inside it (reach search).

For every figure still outside after the calibration, short compass searches (the calibration's
``_compass``) of that figure's own r^2 alone, from the calibrated plant, in stages of growing
departure from what the paper prints or makes plausible. Each stops as soon as the figure is
inside, then pulls every moved value back towards its start as far as the figure stays inside
(the least change of that search that reaches it):

1. ``plausible``: the calibration's parameters within their plausible ranges. Reaching the figure
   here means it conflicts with the other figures (the calibration weighed them all);
2. ``physical``: the same parameters within physical limits (``PHYSICAL``, each with its reason);
3. ``effect NAME``: each declared effect not already on, added, its parameters within their
   declared bounds, the rest at the calibrated values (only when stages 1-2 do not reach);
4. ``printed``: values the paper prints that set the figures (lc, K_I, K_P, ``PRINTED``), moved
   alone. Always run: a variant here contradicts the paper.

Only the figure's own test is simulated during a search; the variant found is then run on every
figure, so the result says what reaching one figure costs the others.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from compliance.effects import EFFECTS
from compliance.model.config import PlantConfig
from compliance.papers import calibration as cal_search
from compliance.papers.calibration_objective import cost, rows_of, within
from compliance.model.parameters import ParamHandle
from compliance.papers.calibration_table import EFFECT_UNSTATED, UNSTATED, unstated
from compliance.papers.plant_a import Row, case_test, scaled_miss

REACH_ITERATIONS = 8  # compass iterations per stage (step 0.1 -> 1/64 of the range takes 3 halvings)
INSIDE = 1.0  # r^2 at the edge of the paper's scatter
TRIM_POLLS, TRIM_ROUNDS = 3, 3  # pulling a moved value back: 3 fractions a round, 3 rounds (1/64 of the move)
UNMEASURED = 1e6  # r^2 of a figure the run does not measure

# physical limits of the calibration's parameters (what a plant of this kind can have at all, not what is plausible)
PHYSICAL: tuple[ParamHandle, ...] = (
    unstated("valve.saturation_voltage", 1.0, 10.0, False,
             "the opening must grow beyond the 0.61/0.69 V dead zone and is reached at most at the 10 V command limit"),
    unstated("friction.coulomb_force", 10.0, 3000.0, True,
             "from a nearly frictionless seal to a fifth of the 16 kN theoretical force"),
    unstated("friction.static_force", 10.0, 4000.0, True, "as the Coulomb force, breakaway up to 1.3 x its top"),
    unstated("friction.stribeck_velocity", 1e-4, 0.1, True, "0.1-100 mm/s: beyond, the seal map is flat"),
    unstated("friction.viscous_coefficient", 10.0, 10000.0, True, "10 N*s/m-10 kN*s/m per cylinder"),
    unstated("controller.filter_cutoff", 2.0, 500.0, True, "2 Hz to the Nyquist frequency of the 1 ms sampling"),
    unstated("flow_control.opening_conductance", 3e-10, 2.33e-8, True,
             "a throttle from nearly shut to fully open (the valve's own 2.33e-8 m^3/(s*Pa))"),
    unstated("flow_control.closing_conductance", 3e-10, 2.33e-8, True, "as the opening throttle"),
    unstated("effects.valve_null_flow.null_opening", 1e-4, 0.05, True, "declared bounds of the effect"),
    unstated("effects.valve_null_flow.null_width", 0.05, 2.0, True, "declared bounds of the effect"),
)
# printed values that set the steady errors and settling times (moving one contradicts the paper)
PRINTED: tuple[ParamHandle, ...] = (
    unstated("controller.compensation_width", 0.02, 2.0, True, "lc, printed 0.4 V"),
    unstated("controller.ki", 0.02, 2000.0, True, "K_I, printed 0.2 (V/(m*s) as read)"),
    unstated("controller.kp", 100.0, 2000.0, True, "K_P, printed 280 V/m"),
)


@dataclass
class Change:
    """One value a reaching variant moved."""

    path: str
    start: float  # calibrated value (effects: the effect's default)
    end: float
    plausible: tuple[float, float] | None  # plausible range, or (printed, printed); None: an added effect
    beyond: str  # how far outside the plausible range / off the printed value ("" when inside)


@dataclass
class Stage:
    """One stage of the reach search of one figure."""

    name: str
    reached: bool
    value: float | None  # the figure at the stage's best point (SI)
    changes: list[Change] = field(default_factory=list)
    cost: float = math.inf  # the whole objective at that point
    inside: int = 0  # figures inside the scatter at that point (of ``compared``)
    compared: int = 0
    pushed_out: list[str] = field(default_factory=list)  # figures inside for the calibrated plant, not here
    evaluations: int = 0


@dataclass
class Reach:
    """The reach search of one figure outside the scatter."""

    test: str
    metric: str
    unit: str
    paper: float
    calibrated: float | None
    stages: list[Stage] = field(default_factory=list)


def _figure_score(cfg: PlantConfig) -> float:
    """Worker objective: r^2 of the one figure in ``_CTX["figure"]``, its test alone simulated."""
    test, metric = cal_search._CTX["figure"]
    rows = rows_of(cfg, cal_search._CTX["conds"][0], targets=cal_search._CTX.get("targets"),
                   tests=frozenset({case_test(test)}))
    row = next((r for r in rows or () if r.test == test and r.metric == metric), None)
    r = None if row is None else scaled_miss(row)
    # uncapped (the calibration's cap would make a far figure's neighbourhood flat); unmeasured: worse than any miss
    return UNMEASURED if r is None or not math.isfinite(r) else r * r


def _beyond(path: str, end: float, ref: tuple[float, float] | None, printed: bool) -> str:
    if ref is None:
        return ""
    lo, hi = ref
    if printed:
        return "" if math.isclose(end, lo, rel_tol=1e-9) else f"x{end / lo:.3g} the printed value"
    if end > hi * (1 + 1e-9):
        return f"x{end / hi:.3g} the plausible top ({hi:.3g})"
    if end < lo * (1 - 1e-9):
        return f"x{end / lo:.3g} the plausible bottom ({lo:.3g})"
    return ""


def _trim(u0: np.ndarray, u: np.ndarray, workers: int) -> tuple[np.ndarray, int]:
    """Pull each moved coordinate back towards ``u0`` as far as the figure stays inside (bisection).

    The fractions of the move kept are polled ``TRIM_POLLS`` at a time on the pool, ``TRIM_ROUNDS`` times,
    so each value ends within (1/(TRIM_POLLS+1))^TRIM_ROUNDS of its move from the edge of the scatter.
    """
    n = 0
    for i in np.flatnonzero(np.abs(u - u0) > 1e-12):
        lo, hi = 0.0, 1.0  # fractions of the move kept: hi reaches, lo is not known to
        for _ in range(TRIM_ROUNDS):
            fracs = [lo + (hi - lo) * k / (TRIM_POLLS + 1) for k in range(1, TRIM_POLLS + 1)]
            if lo == 0.0:
                fracs = [0.0] + fracs
            tasks = []
            for f in fracs:
                t = u.copy()
                t[i] = u0[i] + f * (u[i] - u0[i])
                tasks.append(t)
            res = cal_search._map(tasks, workers)
            n += len(tasks)
            k = next((j for j, r in enumerate(res) if r[0] <= INSIDE), None)
            if k is None:
                lo = fracs[-1]
                continue
            hi = fracs[k]
            if k == 0 and fracs[0] == 0.0:
                break
            lo = fracs[k - 1] if k > 0 else lo
        t = u.copy()
        t[i] = u0[i] + hi * (u[i] - u0[i])
        u = t
    return u, n


def _stage(name: str, cfg0: PlantConfig, table: tuple[ParamHandle, ...], workers: int,
           refs: dict[str, tuple[float, float] | None], printed: bool) -> tuple[Stage, PlantConfig]:
    """Compass the figure's r^2 over ``table`` from ``cfg0``; trim; the stage and its configuration."""
    params = list(table)
    cal_search._CTX.update(cfg=cfg0, params=params)
    u0 = np.array([fp.to_unit(fp.value_in(cfg0)) for fp in params])
    b0 = cal_search._point_cost(cal_search._CTX, u0)
    u, b, n = cal_search._compass(u0, b0, workers, REACH_ITERATIONS, good_enough=INSIDE)
    n += 1
    reached = b[0] <= INSIDE
    if reached:
        u, k = _trim(u0, u, workers)
        n += k
    variant = cal_search._configure(cfg0, params, u)
    test, metric = cal_search._CTX["figure"]
    rows = rows_of(variant, cal_search._CTX["conds"][0], targets=cal_search._CTX.get("targets"),
                   tests=frozenset({case_test(test)})) or []
    value = next((r.simulated for r in rows if (r.test, r.metric) == (test, metric)), None)
    changes = []
    for fp, a, z in zip(params, u0, u):
        if abs(z - a) > 1e-12:
            start, end = fp.from_unit(a), fp.from_unit(z)
            ref = refs.get(fp.path)
            changes.append(Change(fp.path, start, end, ref, _beyond(fp.path, end, ref, printed)))
    return Stage(name, reached, value, changes, evaluations=n), variant


def _fill(stage: Stage, variant: PlantConfig, conditions: dict, base: list[Row]) -> None:
    """The reaching variant on every figure: the objective, how many inside, which it pushes out."""
    rows = rows_of(variant, conditions, targets=cal_search._CTX.get("targets"))
    if rows is None:
        return
    stage.cost = cost(rows)
    stage.inside, stage.compared = within(rows)
    for b, r in zip(base, rows):
        mb, mr = scaled_miss(b), scaled_miss(r)
        if mb is not None and abs(mb) <= 1.0 and not (mr is not None and abs(mr) <= 1.0):
            stage.pushed_out.append(f"{r.test}: {r.metric}")


def reach_figure(cfg: PlantConfig, conditions: dict, row: Row, base: list[Row], workers: int,
                 effects: bool = True, targets: dict | None = None) -> Reach:
    """The reach search of one figure (see the module docstring).

    Parameters
    ----------
    cfg : PlantConfig
        The calibrated configuration.
    conditions : dict
        Its test conditions.
    row : Row
        The figure (``row.paper`` its target, ``row.simulated`` the calibrated value).
    base : list of Row
        Every figure of ``cfg`` (what a reaching variant pushes out is measured against them).
    workers : int
    effects : bool
        Try the declared effects not already on when the calibration's parameters do not reach.
    targets : dict, optional
        (test, metric) -> figure replacing the paper's (``calibration_objective.rows_of``).
    """
    plausible = {u.path: (u.low, u.high) for u in UNSTATED + EFFECT_UNSTATED}
    on = [u for u in UNSTATED + EFFECT_UNSTATED if u.effect is None or u.effect in cfg.effects]
    physical = tuple(u for u in PHYSICAL if any(o.path == u.path for o in on))
    figure = (row.test, row.metric)
    out = Reach(row.test, row.metric, row.unit, row.paper, row.simulated)
    cal_search._CTX.update(conds=[conditions], score=_figure_score, figure=figure, targets=targets)
    try:
        plan = [("plausible", cfg, tuple(on), plausible, False), ("physical", cfg, physical, plausible, False)]
        for name, start, table, refs, printed in plan:
            stage, variant = _stage(name, start, table, workers, refs, printed)
            out.stages.append(stage)
            if stage.reached:
                _fill(stage, variant, conditions, base)
                break
        else:
            if effects:
                for eff in (e for e in EFFECTS if e not in cfg.effects):
                    table = tuple(unstated(f"effects.{eff}.{p.name}", p.bounds[0], p.bounds[1], p.log_scale,
                                           "declared bounds") for p in EFFECTS[eff].params)
                    stage, variant = _stage(f"effect {eff}", cfg.replace(effects={eff: {}}), table, workers, {}, False)
                    out.stages.append(stage)
                    if stage.reached:
                        _fill(stage, variant, conditions, base)
        printed_refs = {u.path: (u.value_in(cfg),) * 2 for u in PRINTED}
        stage, variant = _stage("printed", cfg, PRINTED, workers, printed_refs, True)
        out.stages.append(stage)
        _fill(stage, variant, conditions, base)
    finally:
        for k in ("score", "figure", "targets"):
            cal_search._CTX.pop(k, None)
    return out


def reach_search(cfg: PlantConfig, conditions: dict, rows: list[Row], workers: int,
                 effects: bool = True) -> list[Reach]:
    """The reach search of every figure of ``rows`` (the calibrated plant's) outside the paper's scatter."""
    out = []
    for r in rows:
        m = scaled_miss(r)
        if m is not None and abs(m) > 1.0:
            out.append(reach_figure(cfg, conditions, r, rows, workers, effects))
    return out


def _fmt(v: float | None, unit: str) -> str:
    return "-" if v is None else f"{v * (1e3 if unit == 'mm' else 1.0):.3g} {unit}"


def _changes(stage: Stage) -> str:
    parts = []
    for c in stage.changes:
        name = c.path.split(".")[-1] if not c.path.startswith("effects.") else ".".join(c.path.split(".")[1:])
        txt = f"{name} {c.start:.3g} -> {c.end:.3g}"
        if c.plausible is None:
            txt += " (added effect)"
        elif c.beyond:
            txt += f" ({c.beyond})"
        parts.append(txt)
    return ", ".join(parts) or "nothing"


def format_reach(results: list[Reach]) -> str:
    """Plain text: per figure outside the scatter, what reaches it, at what departure, and what it costs the rest."""
    lines = ["What would reach each figure still outside the scatter (reach search: that figure's r^2 alone, "
             "stages plausible -> physical limits -> added effects -> printed values)"]
    for r in results:
        lines.append(f"  {r.test}: {r.metric}: paper {_fmt(r.paper, r.unit)}, calibrated {_fmt(r.calibrated, r.unit)}")
        for s in r.stages:
            if s.reached or s.name in ("plausible", "physical", "printed"):
                head = f"    {s.name:34s} {'reaches' if s.reached else 'best'} {_fmt(s.value, r.unit):>10s}: {_changes(s)}"
                lines.append(head)
                if s.compared:
                    out = f"; pushes out {'; '.join(s.pushed_out)}" if s.pushed_out else ""
                    lines.append(f"    {'':34s} all figures: cost {s.cost:.1f}, {s.inside} of {s.compared} inside{out}")
        tried = [s.name.split()[1] for s in r.stages if s.name.startswith("effect ") and not s.reached]
        if tried:
            lines.append(f"    added effects that do not reach it: {', '.join(tried)}")
    return "\n".join(lines)


def reach_json(results: list[Reach]) -> list[dict]:
    """The reach search as JSON-ready dicts."""
    import dataclasses

    return [dataclasses.asdict(r) for r in results]

"""Operating maps of the linear figures and the cross-check against the nonlinear simulator.

- ``operating_map``: time constant and margins over stroke x load (and the load curve), so a
  report can show where the IEC 61362 window 0.10-0.25 s holds;
- ``crosscheck``: the linear time constant against the nonlinear step responses (1 % and 5 %
  steps, ``compliance.simulation`` + ``compliance.metrics``, the one metric implementation),
  with the reason for each disagreement.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from compliance.model.pid_controller import stall_error
from compliance import metrics as M
from compliance.model.config import PlantConfig
from compliance.errors import InputError
from compliance.files.jsonable import jsonable
from compliance.linear.analysis import analyse
from compliance.simulation.profiles import steps
from compliance.plants import simulate
from compliance.simulation import Scenario

TAU_WINDOW = (0.10, 0.25)  # IEC 61362 servo-positioner time constant window [s] (seed 000 section 1)
DEFAULT_LOADS = (-2300.0, 0.0, 2000.0, 4000.0, 6000.0, 8000.0, 10000.0, 12000.0)  # [N], seed 000 figs. 9-12 range
MAP_FIGURES = ("time_constant", "dominant_time_constant", "gain_margin_db", "phase_margin_deg", "bandwidth_hz", "damping_ratio")
DISAGREE = 0.20  # |ratio - 1| above which a row gets an explanation (docs/linear.md)

# operating points of the cross-check: (fraction of stroke, load [N] or "curve" or None), the paper's tests
PAPER_POINTS = (
    (0.10, 2300.0),   # fig. 11: 16 mm, closing load
    (0.10, -2300.0),  # fig. 12: 16 mm, opening load
    (0.50, None),     # mid stroke, no load
    (0.50, "curve"),  # mid stroke on the load curve
    (0.80, 11200.0),  # fig. 10: 128 mm, 11.2 kN
    (0.85, 11400.0),  # fig. 9: 136 mm, 11.4 kN
    (0.90, 12000.0),  # 144 mm, nominal load
)


def _load_label(load) -> str:
    if load is None:
        return "none"
    if isinstance(load, str):
        return load
    return f"{load/1e3:+.1f} kN"


@dataclass
class OperatingMap:
    """Linear figures over a grid; ``values[name][i][j]`` at ``loads[i]``, ``positions[j]`` (None: no trim)."""

    positions: list
    loads: list
    values: dict
    notes: list = field(default_factory=list)
    window: tuple = TAU_WINDOW

    def to_dict(self) -> dict:
        """JSON-serialisable map (SI; loads as N, 'curve' or None)."""
        tau = self.values["time_constant"]
        inside = [[None if v is None else bool(self.window[0] <= v <= self.window[1]) for v in row] for row in tau]
        return jsonable({"positions": self.positions, "position_fraction": [x / self.positions[-1] for x in self.positions] if self.positions[-1] else None,
                "loads": self.loads, "window": list(self.window), "values": self.values, "in_window": inside,
                "notes": self.notes})


def operating_map(cfg: PlantConfig, positions=None, loads=None, *, curve: bool = True, flow_control=None, gain: str = "mean") -> OperatingMap:
    """Linear time constant, margins, bandwidth and damping over stroke x load.

    Parameters
    ----------
    cfg : PlantConfig
    positions : sequence of float, optional
        [m]; default 0, 10, ..., 100 % of stroke.
    loads : sequence of float, optional
        Constant closing loads [N]; default ``DEFAULT_LOADS``.
    curve : bool
        Add a row for the configuration's load curve (when it has one).
    """
    L = cfg.p("cylinder.stroke")
    positions = [float(x) for x in (np.linspace(0.0, L, 11) if positions is None else positions)]
    loads = list(DEFAULT_LOADS if loads is None else loads)
    if curve and cfg.load_curve is not None and "curve" not in loads:
        loads.append("curve")
    values = {n: [] for n in MAP_FIGURES + ("stable",)}
    notes = []
    for load in loads:
        rows = {n: [] for n in values}
        for x in positions:
            try:
                a = analyse(cfg, x, load, flow_control=flow_control, gain=gain, detail=False)
            except InputError as exc:
                notes.append(f"{_load_label(load)} at {x*1e3:.0f} mm: {exc}")
                for n in rows:
                    rows[n].append(None)
                continue
            for n in MAP_FIGURES:
                v = a.figures.get(n)
                rows[n].append(None if v is None else float(v))
            rows["stable"].append(bool(a.figures["stable"]))
        for n in values:
            values[n].append(rows[n])
    return OperatingMap(positions, [ld if isinstance(ld, str) or ld is None else float(ld) for ld in loads], values, notes)


def _no_dead_zone(cfg: PlantConfig) -> PlantConfig:
    zero = {f"{k}_{s}": 0.0 for k in ("valve.dead_zone", "controller.compensation_dead_zone") for s in ("positive", "negative")}
    return cfg.replace(params=zero, name=f"{cfg.name} (no dead zone)")


def nonlinear_step(cfg: PlantConfig, position: float, load, fraction: float, *, lead: float = 0.2, duration: float = 3.0, flow_control=None):
    """Simulate one closed-loop step of ``fraction`` of stroke and measure it (``metrics.step_response``)."""
    L = cfg.p("cylinder.stroke")
    ref = steps(f"{fraction * 100.0:.6g}%@{lead}s", position, L, where="cross-check step")
    df = simulate(cfg, Scenario(lead + duration, position, reference=ref, load=load, flow_control=flow_control))
    t, x, r, u = M.frame_columns(df, "time", "position", "reference", "valve_command")
    ev = M.find_steps(t, r)[0]
    u_rel = u - cfg.p("valve.centre_voltage")
    return M.step_response(t, x, ev, valve_command=u_rel, command_saturation=cfg.p("valve.saturation_voltage"))


def viscous_friction_variant(cfg: PlantConfig) -> PlantConfig:
    """The same plant with its friction reduced to the viscous part (what the linear model keeps).

    Variable-viscous model (seed 000 eq. 7) with F_S = F_C = 0, pressure-dependent friction off;
    for the piecewise Stribeck model (seed 001 eq. 8) the viscous slope is k_v2.
    """
    p = cfg.params
    b = p["friction.high_speed_coefficient"] if cfg.options["friction.model"] == "piecewise_stribeck" else p["friction.viscous_coefficient"]
    effects = {"pressure_dependent_friction": None} if "pressure_dependent_friction" in cfg.effects else None
    return cfg.replace(params={"friction.static_force": 0.0, "friction.coulomb_force": 0.0, "friction.limit_velocity": 1e-6,
                               "friction.viscous_coefficient": b},
                       options={"friction.model": "variable_viscous"}, effects=effects, name=f"{cfg.name} (viscous friction only)")


def _explain(row: dict, stall: float, stroke: float) -> str:
    """Short plain reason for a disagreement between the linear and nonlinear time constants (docs/linear.md)."""
    step = abs(row["step"]) * stroke
    if row["tau_nonlinear"] is None:
        return (f"dead zone: valve shut for |e| < {stall*1e3:.2f} mm; stalls at {row['steady_error']*1e3:.2f} mm "
                f"({100*(1-row['steady_error']/step):.0f} % of the step, 63.2 % needed)")
    if row["rate_limited"]:
        return "valve saturation: full opening before 63.2 % (rate limited)"
    if abs(row["ratio"] - 1.0) <= DISAGREE:
        return ""
    rv, rz = row.get("ratio_viscous"), row.get("ratio_viscous_no_dead_zone")
    if rv is not None and abs(rv - 1.0) <= DISAGREE / 2:
        return (f"friction: viscous friction only gives ratio {rv:.2f}; breakaway {row['dead_time']*1e3:.0f} ms "
                f"vs {row['dead_time_viscous']*1e3:.0f} ms")
    if rz is not None and abs(rz - 1.0) <= DISAGREE / 2:
        return f"friction and dead-zone band: viscous friction only {rv:.2f}, also no dead zone {rz:.2f}"
    return f"flow nonlinearity over the step: viscous friction, no dead zone still {rz if rz is None else round(rz, 2)}"


def crosscheck(cfg: PlantConfig, points=None, fractions=(0.01, 0.05), *, flow_control=None) -> list[dict]:
    """Linear vs nonlinear time constant at operating points, one row per step.

    Parameters
    ----------
    cfg : PlantConfig
    points : sequence of (position [m], load), optional
        Default: ``PAPER_POINTS`` scaled to the stroke.
    fractions : sequence of float
        Step sizes as fractions of stroke; each is run up and down where the stroke allows
        (steps under 2 % only up: the 1 % step is the size the dead zone defeats).

    Returns
    -------
    list of dict
        position, load, step (signed fraction), tau_linear (the step direction's valve slope),
        tau_linear_mean, tau_nonlinear (None: never reached 63.2 %), ratio, the same for the
        plant with viscous friction only (``tau_nonlinear_viscous``, ``ratio_viscous``),
        dead_time, steady_error, rate_limited, reason, why (plain text where |ratio - 1| > 20 %).
    """
    L = cfg.p("cylinder.stroke")
    points = [(f * L, ld) for f, ld in PAPER_POINTS] if points is None else list(points)
    visc = viscous_friction_variant(cfg)
    rows = []
    for x, load in points:
        try:
            lin = {g: analyse(cfg, x, load, flow_control=flow_control, gain=g, detail=False) for g in ("mean", "opening", "closing")}
        except InputError as exc:
            rows.append({"position": x, "load": load, "skipped": str(exc)})
            continue
        for frac in fractions:
            for sgn in ((1.0,) if frac < 0.02 else (1.0, -1.0)):
                s = sgn * frac
                if not 0.0 <= x + s * L <= L:
                    continue
                sm = nonlinear_step(cfg, x, load, s, flow_control=flow_control)
                sv = nonlinear_step(visc, x, load, s, flow_control=flow_control)
                a = lin["opening" if s > 0 else "closing"]
                tl, tn, tv = a.figures["time_constant"], sm.time_constant, sv.time_constant
                row = {"position": x, "load": load, "load_force": a.op.load_force, "step": s,
                       "tau_linear": tl, "tau_linear_mean": lin["mean"].figures["time_constant"],
                       "tau_nonlinear": tn, "ratio": (tn / tl) if (tn is not None and tl) else None,
                       "tau_nonlinear_viscous": tv, "ratio_viscous": (tv / tl) if (tv is not None and tl) else None,
                       "dead_time": sm.dead_time, "dead_time_viscous": sv.dead_time, "dead_time_linear": a.figures["dead_time"],
                       "steady_error": sm.steady_state_error, "rate_limited": bool(sm.rate_limited),
                       "reason": sm.reasons.get("time_constant", "")}
                if row["ratio"] is not None and abs(row["ratio"] - 1.0) > DISAGREE and (
                        row["ratio_viscous"] is None or abs(row["ratio_viscous"] - 1.0) > DISAGREE / 2):
                    bare = _no_dead_zone(visc)
                    tz = nonlinear_step(bare, x, load, s, flow_control=flow_control).time_constant
                    tzl = analyse(bare, x, load, flow_control=flow_control, gain="opening" if s > 0 else "closing", detail=False).figures["time_constant"]
                    row["ratio_viscous_no_dead_zone"] = tz / tzl if (tz and tzl) else None
                row["why"] = _explain(row, stall_error(cfg, "opening" if s > 0 else "closing"), L)
                rows.append(row)
    return rows


def crosscheck_table(rows: list[dict]) -> str:
    """Markdown table of ``crosscheck`` rows."""
    out = ["| position | load | step | tau linear | tau nonlinear | ratio | tau nonlinear, viscous friction only | ratio | steady error | note |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    ms = lambda v: "stalled" if v is None else f"{v*1e3:.0f} ms"  # noqa: E731
    rt = lambda v: "-" if v is None else f"{v:.2f}"  # noqa: E731
    for r in rows:
        if "skipped" in r:
            out.append(f"| {r['position']*1e3:.0f} mm | {_load_label(r['load'])} | - | - | - | - | - | - | - | skipped: {r['skipped']} |")
            continue
        load = _load_label(r["load"]) + (f" ({r['load_force']/1e3:.1f} kN)" if isinstance(r["load"], str) else "")
        note = r["why"] or "agrees within 20 %"
        out.append(f"| {r['position']*1e3:.0f} mm | {load} | {r['step']*100:+.0f} % | {ms(r['tau_linear'])} | {ms(r['tau_nonlinear'])} | "
                   f"{rt(r['ratio'])} | {ms(r['tau_nonlinear_viscous'])} | {rt(r['ratio_viscous'])} | "
                   f"{r['steady_error']*1e3:.2f} mm | {note} |")
    return "\n".join(out)


def map_table(m: OperatingMap, name: str = "time_constant", scale: float = 1e3, digits: int = 0) -> str:
    """Plain-text table of one map figure (rows: loads, columns: % stroke); '*' marks the window misses."""
    L = m.positions[-1] if m.positions[-1] else 1.0
    head = "load \\ stroke " + " ".join(f"{100*x/L:6.0f}%" for x in m.positions)
    lines = [head]
    for ld, row in zip(m.loads, m.values[name]):
        cells = []
        for v in row:
            if v is None or (isinstance(v, float) and math.isnan(v)):
                cells.append(f"{'-':>7}")
                continue
            mark = ""
            if name == "time_constant" and not (m.window[0] <= v <= m.window[1]):
                mark = "*"
            cells.append(f"{v*scale:{6 - len(mark)}.{digits}f}{mark} ")
        lines.append(f"{_load_label(ld):>14} " + "".join(cells))
    return "\n".join(lines)

"""The gate servo measured the way a speed governor moves it, for power-system hydro-governor models.

Power-system models reduce the gate servo to a lag with rate and position limits (HYGOV, HYGOV4;
IEEE PES TR "Dynamic Models for Turbine-Governors in Power System Studies", 2013, ch. 3). This
module measures those figures on the nonlinear simulator, all with ONE circuit (the meter-out
flow-control valves 2V2/2V3 in by default: they are the governor's opening/closing-time setting,
seed 000 section 5.2) and ONE load (the configuration's load curve: the force the gate sees):

- Tg: time constant of +/-5 % steps from rest at the operating point (nominal load on the load
  curve), dead time subtracted (``metrics.step_response``, the one IEC 61362 metric); the dead time
  and the dead-zone steady error are kept beside it (HYGOV leaves both out);
- UO/UC: reference steps from rest at the operating points to the far end stop (opening from the
  lower points, closing from the upper ones: what a load pick-up or a load rejection commands),
  gate speed over 25-75 % of stroke (``metrics.stroke_time``) and the peak speed beside it;
- the end-stop strokes of a commissioning stroke-time test, for comparison only.

``compliance.linear.governor_formats`` turns the figures into HYGOV / HYGOV4 / ANDES / PSS/E text.
"""

from __future__ import annotations

import numpy as np

from compliance import metrics as M
from compliance.errors import InputError
from compliance.linear.governor_formats import GovernorModel
from compliance.linear.maps import nonlinear_step
from compliance.model.config import PlantConfig
from compliance.model.pid_controller import stall_error
from compliance.plants import simulate
from compliance.simulation import Scenario
from compliance.simulation.profiles import Profile
from compliance.simulation.scenario import stroke_start_pressures

__all__ = ["OPENING_STARTS", "CLOSING_STARTS", "gate_move", "governor_parameters", "nominal_point"]

# Rest positions [fraction of stroke] the large moves start from (our choice): below 25 % for an
# opening and above 75 % for a closing, so the whole 25-75 % span is crossed; the nominal point is added.
OPENING_STARTS = (0.0, 0.10, 0.20)
CLOSING_STARTS = (0.80, 0.90, 1.00)
MOVE_DURATION = 20.0  # [s] simulated per move: a 25-75 % crossing at 0.05 pu/s still fits


def nominal_point(cfg: PlantConfig) -> tuple[float, float | str | None]:
    """(position [m], load) where the load curve first reaches load.nominal_force; mid stroke without a curve."""
    L = cfg.p("cylinder.stroke")
    if cfg.load_curve is None:
        return 0.5 * L, None
    xs, fs = cfg.load_curve_forces()
    fn = cfg.p("load.nominal_force")
    i = int(np.argmax(fs >= fn)) if np.any(fs >= fn) else int(np.argmax(fs))
    if i > 0 and fs[i] != fs[i - 1] and fs[i] >= fn:
        x = xs[i - 1] + (fn - fs[i - 1]) / (fs[i] - fs[i - 1]) * (xs[i] - xs[i - 1])
    else:
        x = xs[i]
    return float(np.clip(x, 0.0, L)), "curve"


def gate_move(cfg: PlantConfig, start: float, direction: str, load, *, flow_control: bool | None = True,
              from_end_stop: bool = False) -> dict:
    """One closed-loop move from ``start`` [m] to the far end stop, measured like a stroke-time test.

    Parameters
    ----------
    start : float
        Initial position [m]; at rest there (chambers balancing the load, p_A + p_B = p_s + p_atm,
        the simulator's rest state) unless ``from_end_stop`` (the driving side exhausted, the other at
        supply: the state a hold at the end stop leaves, ``stroke_start_pressures``).
    direction : {"opening", "closing"}
    load : float, "curve" or None
        Closing force [N], the configuration's load curve, or none.

    Returns
    -------
    dict
        start [m], direction, rate over 25-75 % of stroke [pu/s] (pu = stroke), the full-stroke time
        it implies [s], peak speed [m/s] and [pu/s], t25/t75 [s] after the reference step.
    """
    L = cfg.p("cylinder.stroke")
    end = L if direction == "opening" else 0.0
    lead = 0.1
    ref = Profile(np.array([0.0, lead, lead]), np.array([start, start, end]))
    p0 = stroke_start_pressures(cfg, direction) if from_end_stop else None
    df = simulate(cfg, Scenario(MOVE_DURATION, start, reference=ref, load=load, flow_control=flow_control,
                                initial_pressures=p0))
    t, x = M.frame_columns(df, "time", "position")
    T, t1, t2, why = M.stroke_time(t, x, L, direction)
    if T is None:
        raise InputError(f"{cfg.path or cfg.name}: {direction} move from {start * 1e3:.0f} mm with load {load!r} "
                         f"did not cross 25-75 % of stroke in {MOVE_DURATION:.0f} s: {why}")
    peak = M.speed_extremes(t, x)[1 if direction == "opening" else 2]
    return {"start": start, "start_pu": start / L, "direction": direction, "from": "end stop" if from_end_stop else "rest",
            "rate_pu_per_s": 1.0 / T, "stroke_time": T, "peak_speed": peak, "peak_pu_per_s": peak / L,
            "t25": t1 - lead, "t75": t2 - lead}


def _starts(cfg: PlantConfig, x_nominal: float) -> tuple[list[float], list[float]]:
    L = cfg.p("cylinder.stroke")
    up = sorted({round(f * L, 9) for f in OPENING_STARTS} | ({round(x_nominal, 9)} if x_nominal <= 0.25 * L else set()))
    down = sorted({round(f * L, 9) for f in CLOSING_STARTS} | ({round(x_nominal, 9)} if x_nominal >= 0.75 * L else set()))
    return up, down


def _tg_steps(cfg: PlantConfig, x: float, load, step: float, flow_control) -> list[dict]:
    """The +/- ``step`` closed-loop steps from rest at ``x``: time constant, dead time, steady error, peak speed."""
    L = cfg.p("cylinder.stroke")
    out = []
    for s in (step, -step):
        if 0.0 <= x + s * L <= L:
            r = nonlinear_step(cfg, x, load, s, flow_control=flow_control)
            out.append({"step": s, "time_constant": r.time_constant, "dead_time": r.dead_time,
                        "steady_error": r.steady_state_error, "peak_speed": r.max_speed,
                        "rate_limited": bool(r.rate_limited), "why": r.reasons.get("time_constant")})
    return out


def governor_parameters(cfg: PlantConfig, *, position: float | None = None, load="default", stroke_load="default",
                        flow_control: bool | None = True, step: float = 0.05, linear=None) -> GovernorModel:
    """Equivalent gate-servo parameters of a plant configuration (HYGOV / HYGOV4 family).

    Parameters
    ----------
    cfg : PlantConfig
    position, load :
        Operating point of Tg [m] and its load; default ``nominal_point`` (nominal load on the load curve).
    stroke_load : float, "curve", None or "default"
        Load during the large moves; default the load curve (the force the gate sees), none without one.
    flow_control : bool or None
        Meter-out flow-control valves for every run (default True: the governor's opening/closing-time
        setting is part of the servo; None: as configured).
    step : float
        Step size for Tg, fraction of stroke (1 % steps stall in the valve dead zone).
    linear : LinearAnalysis, optional
        The linear analysis at the same point (reused for Tg_linear instead of computed again).
    """
    from compliance.linear.analysis import analyse

    L = cfg.p("cylinder.stroke")
    x_n, load_n = nominal_point(cfg)
    x = x_n if position is None else position
    ld = load_n if (isinstance(load, str) and load == "default") else load
    sl = ("curve" if cfg.load_curve is not None else None) if (isinstance(stroke_load, str) and stroke_load == "default") else stroke_load
    steps = _tg_steps(cfg, x, ld, step, flow_control)
    taus = [s["time_constant"] for s in steps if s["time_constant"] is not None]
    if linear is None:
        linear = analyse(cfg, x, ld, flow_control=flow_control, detail=False)
    tg_lin = linear.figures["time_constant"]
    up, down = _starts(cfg, x)
    moves = [gate_move(cfg, s, "opening", sl, flow_control=flow_control) for s in up]
    moves += [gate_move(cfg, s, "closing", sl, flow_control=flow_control) for s in down]
    end_stop = [gate_move(cfg, a, d, sl, flow_control=flow_control, from_end_stop=True) for a, d in ((0.0, "opening"), (L, "closing"))]
    dead = [s["dead_time"] for s in steps if s["dead_time"] is not None]
    return GovernorModel(
        name=cfg.name, stroke=L,
        Tg=float(np.mean(taus)) if taus else tg_lin, Tg_linear=tg_lin,
        Tg_source="nonlinear steps" if taus else "linear model (the nonlinear steps stalled)",
        dead_time=float(np.mean(dead)) if dead else None,
        steady_error={"opening": stall_error(cfg, "opening"), "closing": stall_error(cfg, "closing")},
        point={"position": x, "load": ld, "load_force": linear.op.load_force},
        stroke_load=sl, flow_control=flow_control, steps=steps, moves=moves, end_stop=end_stop)

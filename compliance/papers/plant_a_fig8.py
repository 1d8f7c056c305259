"""Seed 000 fig. 8: 10 % steps with and without the dead-zone compensation, no load, K_D = 6.

The paper's evidence that compensation pays: "a better performance is obtained when
compensation is used ... reducing the settling time". Without compensation the PID output goes
straight to the valve, which stays shut until |K_P*e| exceeds its dead zone, so the servo
stalls zmd/K_P = 2.2 mm short (K_I = 0.2 V/(m*s) needs minutes to wind that up); with the
smoothed inverse of eq. (3) the stall band shrinks to zmd*lc/((zmd + lc)*K_P) = 0.86 mm.

Fig. 8 is lost: the start (40 % of stroke) and the shape (up at 1 s, down at 6 s) are assumed.
Settling is reported two ways: to the settled position (the paper comparison's definition) and
to the set-point (within 1 % of stroke, the IEC 61362 positioning error; None when never).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from compliance.metrics import find_steps, step_response
from compliance.model.config import PlantConfig
from compliance.simulation import Scenario
from compliance.plants import simulate
from compliance.simulation.profiles import steps

X0_FRACTION = 0.4
SPEC = "10%@1s,-10%@6s"
DURATION = 11.0
KD = 6.0
SETPOINT_BAND = 0.01  # of stroke
SETTLING_BAND = 0.05  # of the actual change, the paper comparison's band (plant_a imports this module)


@dataclass
class Fig8Step:
    """One step of fig. 8 under one controller variant."""

    variant: str
    direction: str
    settling_time: float | None  # to the settled position, 5 % band [s]
    setpoint_time: float | None  # to within 1 % of stroke of the set-point [s]
    steady_error: float  # [m]


def _uncompensated(cfg: PlantConfig) -> PlantConfig:
    keys = ("controller.compensation_width", "controller.compensation_dead_zone_positive",
            "controller.compensation_dead_zone_negative")
    return cfg.replace(params={k: 0.0 for k in keys}, sources={k: "user" for k in keys})


def _setpoint_time(t: np.ndarray, x: np.ndarray, t0: float, t1: float, target: float, band: float):
    """Time from t0 to the last entry into |x - target| <= band before t1 (None if outside at t1)."""
    sel = (t >= t0) & (t < t1)
    tt, out = t[sel], np.abs(x[sel] - target) > band
    if out.size == 0 or out[-1]:
        return None
    idx = np.nonzero(out)[0]
    return float(tt[idx[-1] + 1] - t0) if idx.size else 0.0


def fig8(cfg: PlantConfig) -> list[Fig8Step]:
    """Simulate fig. 8 with and without compensation; one entry per step and variant."""
    stroke = cfg.p("cylinder.stroke")
    x0 = X0_FRACTION * stroke
    out = []
    base = cfg.replace(params={"controller.kd": KD}, sources={"controller.kd": "paper"})
    for variant, c in (("with compensation", base), ("without compensation", _uncompensated(base))):
        df = simulate(c, Scenario(duration=DURATION, initial_position=x0, reference=steps(SPEC, x0, stroke), load=None))
        t, x = df.time.to_numpy(), df.position_true.to_numpy()
        for ev in find_steps(t, df.reference.to_numpy()):
            m = step_response(t, x, ev, settling_band=SETTLING_BAND)
            out.append(Fig8Step(variant, "up" if ev.size > 0 else "down", m.settling_time,
                                _setpoint_time(t, x, ev.t_step, ev.t_end, ev.r_after, SETPOINT_BAND * stroke),
                                m.steady_state_error))
    return out


def format_fig8(rows: list[Fig8Step]) -> str:
    """Plain-text table of fig. 8."""
    lines = [f"Fig. 8: 10 % steps, no load, K_D = {KD:g} (start {X0_FRACTION:.0%} of stroke, up at 1 s, down at 6 s; "
             "fig. 8 is lost, these are assumed)",
             f"  {'variant':22s} {'step':5s} {'settling (5 %)':>15s} {'to set-point +/-1 %':>20s} {'steady error':>13s}"]
    for r in rows:
        st = "-" if r.settling_time is None else f"{r.settling_time:.2f} s"
        sp = "never" if r.setpoint_time is None else f"{r.setpoint_time:.2f} s"
        lines.append(f"  {r.variant:22s} {r.direction:5s} {st:>15s} {sp:>20s} {r.steady_error * 1e3:10.2f} mm")
    return "\n".join(lines)

"""Equivalent parameters of the gate servo for power-system hydro-governor models (HYGOV family).

Power-system dynamic models reduce the gate servo to a first-order lag with rate and position
limits: HYGOV (PSS/E, PowerWorld; IEEE PES TR "Dynamic Models for Turbine-Governors in Power
System Studies", 2013, ch. 3) uses the gate servo time constant Tg, one gate velocity limit VELM
[pu/s] and the gate limits GMAX/GMIN [pu]; IEEEG3 and HYGOV4 carry separate opening and closing
rate limits UO and UC [pu/s]. Gate position in pu is x/stroke (0 closed, 1 fully open).

- Tg: the servo-positioner time constant at the nominal operating point, from 5 % steps of the
  nonlinear simulator (what a commissioning step test measures), with the linear value beside it;
- UO/UC: full-stroke closed-loop runs with the flow-control valves installed under a constant
  load (the stroke average of the load curve by default), speed from the straight part of the
  trace (25-75 % of stroke, ``metrics.stroke_time``); VELM = the slower of the two.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field

import numpy as np

from compliance import metrics as M
from compliance.model.config import PlantConfig
from compliance.errors import InputError
from compliance.files.jsonable import jsonable
from compliance.linear.analysis import analyse
from compliance.linear.maps import nonlinear_step
from compliance.simulation.profiles import Profile
from compliance.simulation import Scenario, simulate
from compliance.simulation.scenario import stroke_start_pressures


def nominal_point(cfg: PlantConfig) -> tuple[float, float | str | None]:
    """(position [m], load) where the load curve first reaches load.nominal_force; mid stroke without a curve."""
    L = cfg.p("cylinder.stroke")
    if cfg.load_curve is None:
        return 0.5 * L, None
    xs, fs = cfg.load_curve
    fn = cfg.p("load.nominal_force")
    i = int(np.argmax(fs >= fn)) if np.any(fs >= fn) else int(np.argmax(fs))
    if i > 0 and fs[i] != fs[i - 1] and fs[i] >= fn:
        x = xs[i - 1] + (fn - fs[i - 1]) / (fs[i] - fs[i - 1]) * (xs[i] - xs[i - 1])
    else:
        x = xs[i]
    return float(np.clip(x, 0.0, L)), "curve"


def stroke_average_load(cfg: PlantConfig) -> float | None:
    """Mean closing force of the load curve over the whole stroke [N] (None without a curve)."""
    if cfg.load_curve is None:
        return None
    xs, fs = cfg.load_curve
    x = np.linspace(0.0, cfg.p("cylinder.stroke"), 2001)
    return float(np.mean(np.interp(x, xs, fs)))


def stroke_speed(cfg: PlantConfig, direction: str, load, *, flow_control: bool = True, timeout: float = 30.0) -> dict:
    """Full-stroke closed-loop run: a reference step from one end stop to the other, speed from 25-75 % of stroke.

    Returns
    -------
    dict
        direction, full-stroke time [s] (extrapolated from 25-75 %), speed [m/s], rate [pu/s],
        peak speed [m/s], t25/t75 [s].
    """
    L = cfg.p("cylinder.stroke")
    x0, x1 = (0.0, L) if direction == "opening" else (L, 0.0)
    ref = Profile(np.array([0.0, 0.1, 0.1]), np.array([x0, x0, x1]))
    # from the end stop as the hold there leaves the chambers, like the full_stroke procedure
    df = simulate(cfg, Scenario(timeout, x0, reference=ref, load=load, flow_control=flow_control,
                                initial_pressures=stroke_start_pressures(cfg, direction)))
    t, x = M.frame_columns(df, "time", "position")
    T, t1, t2, why = M.stroke_time(t, x, L, direction)
    if T is None:
        raise InputError(f"{cfg.path or cfg.name}: full-stroke {direction} run with load {load!r} failed: {why}")
    vmax = M.speed_extremes(t, x)[1 if direction == "opening" else 2]
    return {"direction": direction, "stroke_time": T, "speed": L / T, "rate_pu_per_s": 1.0 / T, "peak_speed": vmax, "t25": t1, "t75": t2}


@dataclass
class GovernorModel:
    """HYGOV-style equivalent parameters with their basis."""

    Tg: float
    Tg_linear: float | None
    UO: float
    UC: float
    GMAX: float = 1.0
    GMIN: float = 0.0
    basis: dict = field(default_factory=dict)

    @property
    def VELM(self) -> float:
        """HYGOV's single gate velocity limit [pu/s]: the slower of opening and closing."""
        return min(self.UO, abs(self.UC))

    def to_dict(self) -> dict:
        """JSON-serialisable parameters, units and basis."""
        return jsonable({
            "model": "HYGOV",
            "parameters": {"Tg": self.Tg, "VELM": self.VELM, "GMAX": self.GMAX, "GMIN": self.GMIN},
            "rate_limits": {"UO": self.UO, "UC": self.UC},
            "units": {"Tg": "s", "VELM": "pu/s", "GMAX": "pu", "GMIN": "pu", "UO": "pu/s", "UC": "pu/s (negative: closing)"},
            "Tg_linear": self.Tg_linear,
            "basis": self.basis,
        })

    def to_json(self) -> str:
        """The parameters as a JSON document."""
        return json.dumps(self.to_dict(), indent=2)

    def table(self) -> str:
        """Plain parameter table."""
        rows = [("Tg", f"{self.Tg:.3f}", "s", "gate servo time constant (nonlinear 5 % steps at the nominal point)"),
                ("Tg (linear)", "-" if self.Tg_linear is None else f"{self.Tg_linear:.3f}", "s", "same, from the linear model"),
                ("VELM", f"{self.VELM:.4f}", "pu/s", "gate velocity limit (HYGOV, slower direction)"),
                ("UO", f"{self.UO:.4f}", "pu/s", f"max opening rate (full stroke {1/self.UO:.2f} s)"),
                ("UC", f"{self.UC:.4f}", "pu/s", f"max closing rate (full stroke {1/abs(self.UC):.2f} s)"),
                ("GMAX", f"{self.GMAX:.2f}", "pu", "maximum gate (stroke end)"),
                ("GMIN", f"{self.GMIN:.2f}", "pu", "minimum gate (closed)")]
        w = max(len(r[0]) for r in rows)
        return "\n".join(f"{n:<{w}}  {v:>8} {u:<5} {m}" for n, v, u, m in rows)


def governor_parameters(cfg: PlantConfig, *, position: float | None = None, load="default", stroke_load="default",
                        step: float = 0.05) -> GovernorModel:
    """Equivalent HYGOV parameters of a plant configuration.

    Parameters
    ----------
    cfg : PlantConfig
    position, load :
        Operating point of Tg [m], load; default ``nominal_point`` (nominal load on the load curve).
    stroke_load : float, "curve" or None
        Load during the full-stroke runs; default a constant force equal to the stroke average of
        the load curve (a straight trace whose speed is the average rate; 5.9 kN for plant A, near
        the 5.7 kN at which seed 000 set its throttles), none without a curve. "curve" follows the
        curve (speed then varies along the stroke; 25-75 % gives the average over that span).
    step : float
        Step size for Tg, fraction of stroke (5 %: 1 % steps stall in the valve dead zone).
    """
    L = cfg.p("cylinder.stroke")
    x_n, load_n = nominal_point(cfg)
    x = x_n if position is None else position
    ld = load_n if (isinstance(load, str) and load == "default") else load
    sl = stroke_average_load(cfg) if (isinstance(stroke_load, str) and stroke_load == "default") else stroke_load
    taus = []
    for s in (step, -step):
        if 0.0 <= x + s * L <= L:
            tau = nonlinear_step(cfg, x, ld, s).time_constant
            if tau is not None:
                taus.append(tau)
    lin = analyse(cfg, x, ld, detail=False).figures["time_constant"]
    tg = float(np.mean(taus)) if taus else lin
    up = stroke_speed(cfg, "opening", sl)
    down = stroke_speed(cfg, "closing", sl)
    basis = {"Tg_point": {"position": x, "load": ld}, "Tg_steps": [step, -step], "Tg_nonlinear_samples": taus,
             "Tg_source": "nonlinear 5 % steps" if taus else "linear model (nonlinear steps stalled)",
             "stroke_runs": {"load": sl, "flow_control": True, "opening": up, "closing": down,
                             "method": "closed loop, reference step end to end, 25-75 % of stroke extrapolated"}}
    return GovernorModel(tg, lin, up["rate_pu_per_s"], -down["rate_pu_per_s"], basis=basis)

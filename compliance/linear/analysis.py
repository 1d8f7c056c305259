"""Linearised analysis of the gate servo with python-control at one operating point.

Trim and Jacobians come from ``compliance.linear.trim`` (the one ``plant_rhs``). Here the
plant u_d [V] -> position [m] becomes a ``control.StateSpace``, is closed with the configured
PID (derivative on the first-order filtered measurement, as ``compliance.simulation`` runs it),
continuous and at the controller sample time (plant by ZOH, ``control.c2d``; controller by
the exact difference equations of ``compliance.model.pid_controller``), and the figures are measured.
Choices and limits of the linear model: docs/linear.md.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import control
import numpy as np

from compliance import metrics as M
from compliance.effects import EFFECTS
from compliance.model.config import PlantConfig
from compliance.model.pid_controller import first_order_filter_gain
from compliance.errors import InputError
from compliance.model.vector_slots import P_BV, P_MASS, P_NFR, P_STROKE
from compliance.files.jsonable import json_number, jsonable  # the one JSON cleaner (re-exported for linear/*)
from compliance.plants import kind_of
from compliance.linear.trim import TrimPoint, linearise_plant, minimal_realisation, pneumatic_stiffness, trim

PADE_ORDER = 3  # delays as 3rd-order Pade: phase error < 1 deg up to omega*T = 2 (well beyond crossover)
STEP_FRACTION = 0.05  # predicted step: 5 % of stroke (the linear shape does not depend on the size)
_PID_INPUTS = ["reference_m", "position_measured_m"]  # python-control names carry the unit after the last underscore
METRIC_NAMES = ("time_constant", "gain_margin_db", "phase_margin_deg", "bandwidth_hz", "damping_ratio",
                "pneumatic_damping_ratio", "natural_frequency_hz", "dominant_time_constant")


def _pade_ss(delay, order=PADE_ORDER):
    if delay <= 0.0:
        return None
    num, den = control.pade(delay, order)
    return control.ss(control.tf(num, den))


def pid_controller(cfg: PlantConfig, discrete: bool = False) -> control.StateSpace:
    """The configured PID as a two-input system [r, x_measured] -> u_d [V].

    Continuous: u = K_P e + K_I int(e) - K_D s x_f with x_f = x/(1 + s/w_f), w_f = 2 pi f_c.
    Discrete: exactly ``compliance.model.pid_controller.pid_step`` with the ZOH filter gain alpha (integral
    updated before use, rate = (x_f[k] - x_f[k-1])/T_s), so it matches the simulator sample for sample.
    """
    kp, ki, kd = cfg.p("controller.kp"), cfg.p("controller.ki"), cfg.p("controller.kd")
    ts, fc = cfg.p("controller.sample_time"), cfg.p("controller.filter_cutoff")
    if discrete:
        a = first_order_filter_gain(fc, ts)  # alpha = 1 - exp(-w_f T_s)
        k0 = kp + ki * ts
        return control.ss([[1.0, 0.0], [0.0, 1.0 - a]], [[ts, -ts], [0.0, a]], [[ki, kd * a / ts]],
                          [[k0, -k0 - kd * a / ts]], ts, inputs=_PID_INPUTS, outputs=["u_d_V"])
    if fc <= 0.0:
        raise InputError(f"{cfg.path or cfg.name}: controller.filter_cutoff must be > 0 for the continuous linear model")
    wf = 2.0 * math.pi * fc
    return control.ss([[0.0, 0.0], [0.0, -wf]], [[1.0, -1.0], [0.0, wf]], [[ki, kd * wf]],
                      [[kp, -kp - kd * wf]], inputs=_PID_INPUTS, outputs=["u_d_V"])


def _augment(cfg: PlantConfig, plant: control.StateSpace) -> control.StateSpace:
    """u_d -> [x, x_measured]: declared input delays (Pade) before the plant, declared
    measurement lags and delays after it (``Effect.input_delay``, ``output_lag``, ``output_delay``)."""
    g = plant
    h = control.ss([], [], [], [[1.0]])
    for name, values in cfg.effects.items():
        eff = EFFECTS[name]
        d_in = _pade_ss(values[eff.input_delay]) if eff.input_delay else None
        if d_in is not None:
            g = control.series(d_in, g)
        tau = values[eff.output_lag] if eff.output_lag else 0.0
        if tau > 0.0:
            h = control.series(h, control.ss([[-1.0 / tau]], [[1.0 / tau]], [[1.0]], [[0.0]]))
        d_out = _pade_ss(values[eff.output_delay]) if eff.output_delay else None
        if d_out is not None:
            h = control.series(h, d_out)
    gm = control.series(g, h)
    n1, n2 = g.nstates, gm.nstates
    # stack [x; xm] over the states of gm (g's states come first in control.series(g, h))
    A, B = gm.A, gm.B
    C = np.vstack([np.hstack([g.C, np.zeros((1, n2 - n1))]), gm.C])
    return control.ss(A, B, C, np.zeros((2, 1)), inputs=["u_d_V"], outputs=["position_m", "position_measured_m"])


def _close(g2: control.StateSpace, k: control.StateSpace) -> control.StateSpace:
    """Closed loop r -> x of a plant [x; xm] (D = 0) and a controller [r, xm] -> u."""
    Ag, Bg, Cg = g2.A, g2.B, g2.C
    Ak, Bk, Ck, Dk = k.A, k.B, k.C, k.D
    c_x, c_m = Cg[:1], Cg[1:2]
    A = np.block([[Ag + Bg @ Dk[:, 1:2] @ c_m, Bg @ Ck], [Bk[:, 1:2] @ c_m, Ak]])
    B = np.vstack([Bg @ Dk[:, 0:1], Bk[:, 0:1]])
    C = np.hstack([c_x, np.zeros((1, Ak.shape[0]))])
    return control.ss(A, B, C, [[0.0]], g2.dt, inputs=["reference_m"], outputs=["position_m"])


def close_loop(cfg: PlantConfig, plant: control.StateSpace, discrete: bool = False):
    """Close the configured PID around a plant u_d [V] -> position [m].

    Parameters
    ----------
    cfg : PlantConfig
        Controller gains, sample time, filter cut-off; sensor and valve delays of its effects.
    plant : control.StateSpace
        Continuous SISO plant (D = 0).
    discrete : bool
        False: continuous loop. True: plant discretised by ZOH at controller.sample_time
        (``control.c2d``) with the simulator's exact difference-equation PID.

    Returns
    -------
    tuple
        (closed loop r -> x, loop transfer L broken at the valve command).
    """
    g2 = _augment(cfg, plant)
    k = pid_controller(cfg, discrete)
    if discrete:
        g2 = control.c2d(g2, cfg.p("controller.sample_time"), "zoh")
    return _close(g2, k), _loop(g2, k)


def _loop(g2, k):
    """Loop transfer L = C_y * G_m (broken at the valve command), for margins and Nyquist."""
    cy = control.ss(k.A, k.B[:, 1:2], -k.C, -k.D[:, 1:2], k.dt, inputs=["position_measured_m"], outputs=["u_d_return_V"])
    gm = control.ss(g2.A, g2.B, g2.C[1:2], [[0.0]], g2.dt, inputs=["u_d_V"], outputs=["position_measured_m"])
    L = control.series(gm, cy)
    return control.ss(L.A, L.B, L.C, L.D, L.dt, inputs=["u_d_V"], outputs=["u_d_return_V"])


def _damping(p):
    wn = abs(p)
    return wn, (-p.real / wn if wn > 0 else 1.0)


def _pairs(z):
    return [[float(v.real), float(v.imag)] for v in np.atleast_1d(z)]


def _step_metrics(t, y, x0, size):
    ev = M.StepEvent(0.0, float(t[-1]), x0, x0 + size)
    return M.step_response(t, x0 + size * np.asarray(y), ev)


def _modes(sys):
    """Poles p_i and impulse residues r_i of a continuous SISO system: G(s) = D + sum r_i/(s - p_i).

    A defective A (repeated poles without a full set of eigenvectors) has no such expansion;
    then every residue is reported as 1 (all modes count as significant).
    """
    lam, V = np.linalg.eig(sys.A)
    if np.linalg.cond(V) > 1e12:
        return lam, np.ones_like(lam)
    w = np.linalg.solve(V, sys.B[:, 0])
    return lam, (sys.C[0] @ V) * w


@dataclass
class LinearAnalysis:
    """Everything the linear model says at one operating point (SI; see ``to_dict``)."""

    op: TrimPoint
    plant: control.StateSpace
    plant_minimal: control.StateSpace
    loop: control.StateSpace
    loop_discrete: control.StateSpace
    closed_loop: control.StateSpace
    closed_loop_discrete: control.StateSpace
    figures: dict = field(default_factory=dict)
    data: dict = field(default_factory=dict)
    info: dict = field(default_factory=dict)

    def metric(self, name: str) -> float:
        """One figure by name (``METRIC_NAMES``)."""
        if name not in METRIC_NAMES:
            raise InputError(f"linear metric '{name}' is not known (known: {', '.join(METRIC_NAMES)})")
        v = self.figures[name]
        return float("nan") if v is None else float(v)

    def to_dict(self) -> dict:
        """JSON-serialisable result: operating point, matrices, figures, Bode/Nyquist/step arrays."""
        return jsonable({
            "operating_point": self.op.to_dict(),
            "plant": {"states": list(self.plant.state_labels), "A": self.plant.A.tolist(), "B": self.plant.B.tolist(),
                      "C": self.plant.C.tolist(), "input": "u_d [V]", "output": "position [m]"},
            "figures": self.figures,
            "linearisation": self.info,
            **self.data,
        })


def analyse(cfg: PlantConfig, position: float, load: float | str | None = None, *, flow_control: bool | None = None,
            gain: str = "mean", n_freq: int = 200, detail: bool = True) -> LinearAnalysis:
    """Trim, linearise, close the loop and measure every linear figure at one operating point.

    Parameters
    ----------
    cfg : PlantConfig
        A plant whose kind has the closed-loop linear model (``PlantKind.linear_support``: the PID servo).
    position : float
        Operating point [m].
    load : float, "curve" or None
        Closing load [N] (> 0 closes), the load curve, or none.
    flow_control : bool or None
        Override the meter-out flow-control valves.
    gain : {"mean", "opening", "closing"}
        Which slope of the compensated valve to use (mean = describing function of a small
        oscillation about null).
    n_freq : int
        Points of the Bode / Nyquist arrays.
    detail : bool
        False skips the arrays and the continuous-time step and margins (operating maps).
    """
    kind_of(cfg).check_linear(cfg)
    op = trim(cfg, position, load, flow_control=flow_control)
    A, B, C, names, info = linearise_plant(op, cfg, gain)
    plant = control.ss(A, B, C, [[0.0]], states=names, inputs=["u_d_V"], outputs=["position_m"])
    Am, Bm, Cm = minimal_realisation(A, B, C, np.array(info["state_scales"]))
    if Am.size == 0:  # nothing of the valve command reaches the position at the numerical precision of the scales
        raise InputError(
            f"{cfg.path or cfg.name}: the linearised plant at {op.position * 1e3:.1f} mm has no mode from the valve command "
            f"to the position left (every mode is numerically uncontrollable or unobservable); the states differ in "
            f"speed beyond what double precision resolves - check cylinder.moving_mass = {cfg.p('cylinder.moving_mass'):g} kg "
            "and the other scales of the configuration")
    gmin = control.ss(Am, Bm, Cm, [[0.0]], inputs=["u_d_V"], outputs=["position_m"])
    T, Lc = close_loop(cfg, gmin)
    Td, Ld = close_loop(cfg, gmin, discrete=True)
    figs, data = _figures(cfg, op, plant, gmin, Lc, Ld, T, Td, n_freq, detail)
    info["unobservable_or_uncontrollable_states"] = plant.nstates - gmin.nstates
    return LinearAnalysis(op, plant, gmin, Lc, Ld, T, Td, figs, data, info)


def margins(loop, floor_hz: float = 0.0, n: int = 600) -> dict:
    """Gain margin [dB], phase margin [deg] and their crossover frequencies [Hz] (``control.stability_margins``).

    The loop is evaluated from its state space on ``n`` log-spaced frequencies (from
    ``floor_hz`` to the Nyquist frequency, or 100x the fastest pole) and the margins are taken from
    that frequency-response data: python-control's 'poly' method goes through polynomial
    coefficients, which lose all accuracy for a sampled loop with several poles near z = 1. A gain
    crossover below ``floor_hz`` (an integral action strong enough to reach it) is looked for from
    1e-3 rad/s. Phase crossovers below ``floor_hz`` are ignored: with integral action on an integrating
    plant the loop phase tends to -180 deg as w -> 0 (type-2 loop) without crossing it. The least
    margin of the remaining crossings is returned; a margin that does not exist is None.
    """
    dt = loop.dt if loop.dt not in (None, 0, True) else None
    if dt:
        hi = math.pi / dt * (1 - 1e-9)
    else:
        hi = 100.0 * max([1.0] + [abs(p) for p in np.atleast_1d(loop.poles())] + [abs(z) for z in np.atleast_1d(loop.zeros())])
    for lo in (max(2 * math.pi * floor_hz, 1e-3), 1e-3):
        w = np.logspace(math.log10(lo), math.log10(hi), n)
        fr = control.frequency_response(loop, w)
        data = control.frd(fr.complex.reshape(-1), w, dt=dt if dt else 0)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)
            gm, pm, _, wpc, wgc, _ = control.stability_margins(data, returnall=True)
        if np.any(np.isfinite(np.atleast_1d(pm))):
            break  # else a strong integral action put the gain crossover below the floor: look from 1e-3 rad/s
    gm, wpc = np.atleast_1d(gm), np.atleast_1d(wpc)
    keep = (wpc >= 2 * math.pi * floor_hz) & np.isfinite(gm) & (gm > 0)
    out = {"gain_margin_db": None, "phase_crossover_hz": None, "phase_margin_deg": None, "gain_crossover_hz": None}
    if np.any(keep):
        i = int(np.argmin(gm[keep]))
        out["gain_margin_db"] = 20 * math.log10(gm[keep][i])
        out["phase_crossover_hz"] = float(wpc[keep][i] / (2 * math.pi))
    pm, wgc = np.atleast_1d(pm), np.atleast_1d(wgc)
    if pm.size and np.any(np.isfinite(pm)):
        j = int(np.nanargmin(pm))
        out["phase_margin_deg"], out["gain_crossover_hz"] = float(pm[j]), float(wgc[j] / (2 * math.pi))
    return out


def _figures(cfg, op, plant, gmin, Lc, Ld, T, Td, n_freq, detail):
    P = op.params
    kp, kd = cfg.p("controller.kp"), cfg.p("controller.kd")
    ts = cfg.p("controller.sample_time")
    f = {}
    # pneumatic mode: the plant pole pair nearest the analytic spring-mass frequency
    k_pn = pneumatic_stiffness(op)
    w_an = math.sqrt(k_pn / P[P_MASS])
    pp = gmin.poles()
    cand = [p for p in pp if p.imag > 0] or [p for p in pp if abs(p) > 1e-6 * w_an]
    pn = min(cand, key=lambda p: abs(abs(p) - w_an)) if cand else complex(-w_an, 0)
    f["natural_frequency_hz"], f["pneumatic_damping_ratio"] = _damping(pn)[0] / (2 * math.pi), _damping(pn)[1]
    f["pneumatic_stiffness"] = k_pn
    f["natural_frequency_analytic_hz"] = w_an / (2 * math.pi)
    f["viscous_damping_ratio_analytic"] = P[P_BV] * P[P_NFR] / (2 * math.sqrt(k_pn * P[P_MASS]))
    # open-loop gain: velocity per volt = residue of the integrator (slowest) mode of the plant
    lam, r = _modes(gmin)
    kq = float(np.real(r[int(np.argmin(np.abs(lam)))]))  # = lim s->0 s*G(s) for a pure integrator
    f["plant_velocity_gain"] = kq
    f["loop_gain"] = kp * kq
    f["first_order_time_constant"] = (1.0 + kq * kd) / (kq * kp) if kq > 0 else None
    # closed loop
    pcl = T.poles()
    lam, r = _modes(T)
    # size of each mode in the step response; a pole at the origin (an integrator state K_I = 0 leaves unused) has none
    with np.errstate(divide="ignore", invalid="ignore"):
        amp = np.where(np.abs(lam) > 1e-12, np.abs(r / np.where(lam == 0, 1.0, lam)), 0.0)
    sig = amp >= 0.05 * max(np.max(amp), 1e-300)
    dom = lam[sig][np.argmin(np.abs(lam[sig].real))]
    f["dominant_time_constant"] = -1.0 / dom.real if dom.real < 0 else None
    f["damping_ratio"] = float(min(_damping(p)[1] for p in pcl if abs(p) > 0)) if len(pcl) else None
    f["stable"] = bool(np.all(pcl.real < 0)) and bool(np.all(np.abs(Td.poles()) < 1.0))
    floor = 10.0 * cfg.p("controller.ki") / kp / (2 * math.pi)  # integral-action region (see margins)
    f.update(margins(Ld, floor))  # the sampled loop is what runs; the continuous margins are for reference
    if detail:
        mc = margins(Lc, floor)
        f.update(gain_margin_db_continuous=mc["gain_margin_db"], phase_margin_deg_continuous=mc["phase_margin_deg"])
    f["bandwidth_hz"] = json_number(control.bandwidth(T) / (2 * math.pi)) if f["stable"] else None
    # predicted step (discrete closed loop: what the sampled controller does) and its time constant
    tau_guess = f["dominant_time_constant"] or f["first_order_time_constant"] or 0.2
    dur = float(np.clip(12.0 * tau_guess, 1.5, 30.0))
    n = int(round(dur / ts))
    size = STEP_FRACTION * P[P_STROKE] * (1 if op.position + STEP_FRACTION * P[P_STROKE] <= P[P_STROKE] else -1)
    td = np.arange(n + 1) * ts
    yd = control.step_response(Td, td).outputs
    sm = _step_metrics(td, yd, op.position, size)
    f.update(time_constant=sm.time_constant, dead_time=sm.dead_time, rise_time=sm.rise_time,
             settling_time=sm.settling_time, overshoot=sm.overshoot)
    if not f["stable"]:  # a diverging response has no time constant: the figures would mislead
        f.update(time_constant=None, dead_time=None, rise_time=None, settling_time=None, overshoot=None,
                 dominant_time_constant=None)
    if not detail:
        return f, {"poles": {"closed_loop": _pairs(pcl), "pneumatic": [float(pn.real), float(pn.imag)]}}
    tc = np.linspace(0.0, dur, 2001)
    yc = control.step_response(T, tc).outputs
    f["time_constant_continuous"] = _step_metrics(tc, yc, op.position, size).time_constant
    # arrays for the report
    w = np.logspace(-1, math.log10(math.pi / ts), n_freq)
    Lr, Tr = control.frequency_response(Lc, w), control.frequency_response(T, w)
    Ldr = control.frequency_response(Ld, w)
    keep = np.unique(np.linspace(0, n, min(n + 1, 600)).astype(int))
    data = {
        "poles": {"plant": _pairs(plant.poles()), "plant_minimal": _pairs(gmin.poles()), "plant_zeros": _pairs(gmin.zeros()),
                  "closed_loop": _pairs(pcl), "closed_loop_zeros": _pairs(T.zeros()),
                  "closed_loop_discrete": _pairs(Td.poles()), "pneumatic": [float(pn.real), float(pn.imag)]},
        "bode": {"frequency_hz": (w / (2 * math.pi)).tolist(),
                 "loop_magnitude_db": (20 * np.log10(np.abs(Lr.complex))).tolist(),
                 "loop_phase_deg": np.degrees(np.unwrap(np.angle(Lr.complex))).tolist(),
                 "loop_discrete_magnitude_db": (20 * np.log10(np.abs(Ldr.complex))).tolist(),
                 "loop_discrete_phase_deg": np.degrees(np.unwrap(np.angle(Ldr.complex))).tolist(),
                 "closed_loop_magnitude_db": (20 * np.log10(np.abs(Tr.complex))).tolist(),
                 "closed_loop_phase_deg": np.degrees(np.unwrap(np.angle(Tr.complex))).tolist()},
        "nyquist": {"frequency_hz": (w / (2 * math.pi)).tolist(), "loop_real": Ldr.complex.real.tolist(),
                    "loop_imag": Ldr.complex.imag.tolist()},
        "step": {"size": size, "time": td[keep].tolist(), "position": (op.position + size * yd[keep]).tolist(),
                 "time_continuous": tc[::4].tolist(), "position_continuous": (op.position + size * yc[::4]).tolist()},
    }
    return f, data


_CACHE: dict = {}


def linear_metric(cfg: PlantConfig, name: str, position: float, load: float | str | None = None) -> float:
    """One linear figure at an operating point, for requirement files (``METRIC_NAMES``).

    Parameters
    ----------
    cfg : PlantConfig
    name : str
        ``time_constant`` [s], ``gain_margin_db`` [dB], ``phase_margin_deg`` [deg],
        ``bandwidth_hz`` [Hz], ``damping_ratio`` [-] (least-damped closed-loop mode), and
        ``pneumatic_damping_ratio``, ``natural_frequency_hz``, ``dominant_time_constant``.
    position : float
        [m].
    load : float, "curve", None or a string with a unit ("11.4 kN")
    """
    if name not in METRIC_NAMES:
        raise InputError(f"linear metric '{name}' is not known (known: {', '.join(METRIC_NAMES)})")
    if isinstance(load, str) and load.strip().lower() not in ("curve", "none", ""):
        from compliance.units import parse_quantity

        try:
            load = float(load)
        except ValueError:
            load = parse_quantity(load, "N", f"linear metric '{name}': load")
    elif isinstance(load, str) and load.strip().lower() in ("none", ""):
        load = None
    key = (id(cfg), float(position), load if isinstance(load, str) or load is None else float(load))
    hit = _CACHE.get(key)
    if hit is None or hit[0] is not cfg:
        if len(_CACHE) > 32:
            _CACHE.clear()
        _CACHE[key] = hit = (cfg, analyse(cfg, float(position), load, detail=False))
    return hit[1].metric(name)

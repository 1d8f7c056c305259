"""The measured gate servo as power-system governor-model parameters: HYGOV, HYGOV4, ANDES, PSS/E.

Conventions (docs/linear.md section 7): gate in per unit = x / stroke (0 closed, 1 fully open) on
the MACHINE base (the turbine's own rating: 1 pu gate = full stroke, whatever its MVA); rates in
pu/s of that; UC negative (closing), as in PSS/E HYGOV4 and ANDES's HYGOV4 limiter.

Model structure (read from the ANDES 2.0 source, ``andes/models/governor/hygov.py`` and
``hygov4.py``; PSS/E Model Library HYGOV for the .dyr order):

- HYGOV: speed error -> filter Tf -> PI (integrator c, temporary droop r, Tr) -> gate lag Tg.
  VELM limits the rate of the INTEGRATOR c, not of the gate; the gate follows c through the Tg
  lag, so in a long move the gate speed settles at VELM one Tg after c starts ramping.
- HYGOV4: pilot servo lag Tp -> gain 1/Tg -> gate-velocity limits [UC, UO] -> gate integrator,
  closed by the droop feedback Rperm + Rtemp Tr s/(1 + Tr s). The limits act on the gate itself.
  With the feedback at unity (Rperm = 1 pu on the system base, Rtemp = 0) the gate is a lag Tg
  with separate opening/closing rate limits: the bare positioner this module describes.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field

from compliance.files.jsonable import jsonable

__all__ = ["GovernorModel", "HYGOV_DYR_ORDER", "ANDES_MODELS"]

# PSS/E HYGOV CONs in .dyr order after BUS 'HYGOV' ID (PSS/E Model Library; ANDES io/psse-dyr.yaml)
HYGOV_DYR_ORDER = ("R", "r", "Tr", "Tf", "Tg", "VELM", "GMAX", "GMIN", "Tw", "At", "Dturb", "qNL")
ANDES_MODELS = ("HYGOV", "HYGOVDB", "HYGOV4")  # ANDES 2.0's hydro governors (no IEEEG3)
HYGOV4_RATIO = 0.10  # opening/closing rates differing by more than this favour HYGOV4 (our choice)
SYSTEM_MVA = 100.0  # [MVA] the system base of PSS/E and ANDES cases unless they say otherwise (SBASE, config.mva)
# The bare positioner in HYGOV: the speed-governor loop made transparent so the gate follows its set-point
# through the servo's own lag and rate limit (our choices, each far from the servo's time scales):
DESIRED_GATE_TAU = 0.01  # [s] 1/R on the system base: the desired gate follows the set-point 23x faster than Tg
TEMPORARY_DROOP = 1e6  # r on the system base: no proportional path (ANDES shifts the rate bounds by LG_y/r)
FILTER_TAU = 1e-3  # [s] Tf: the input filter, 10x faster than the desired-gate loop


@dataclass
class GovernorModel:
    """The measured gate-servo figures (SI, gate in pu of stroke) and their basis."""

    name: str
    stroke: float  # [m]
    Tg: float  # [s] time constant of the nonlinear steps, dead time subtracted
    Tg_linear: float | None  # [s] the linear model at the same point
    Tg_source: str
    dead_time: float | None  # [s] mean dead time of the steps
    steady_error: dict  # direction -> [m] dead-zone stall band (model.pid_controller.stall_error)
    point: dict  # position [m], load, load_force [N]
    stroke_load: object  # load of the large moves: N, "curve" or None
    flow_control: bool | None
    steps: list = field(default_factory=list)  # the Tg steps
    moves: list = field(default_factory=list)  # from rest at the operating points
    end_stop: list = field(default_factory=list)  # commissioning strokes from the end stops (comparison)
    GMAX: float = 1.0
    GMIN: float = 0.0
    study: dict = field(default_factory=dict)  # rating_mva, system_mva, dispatch_mw of the exported ANDES / PSS/E forms

    def _best(self, direction: str, key: str) -> float:
        return max(m[key] for m in self.moves if m["direction"] == direction)

    @property
    def UO(self) -> float:
        """Opening gate velocity [pu/s]: the fastest 25-75 % rate of the openings from rest."""
        return self._best("opening", "rate_pu_per_s")

    @property
    def UC(self) -> float:
        """Closing gate velocity [pu/s] (negative): the fastest 25-75 % rate of the closings from rest."""
        return -self._best("closing", "rate_pu_per_s")

    @property
    def VELM(self) -> float:
        """HYGOV's single velocity limit [pu/s]: the faster direction (our choice: a slower model gate under-
        states the water-hammer pressure rise of a load rejection and the overspeed it limits)."""
        return max(self.UO, -self.UC)

    @property
    def family(self) -> dict:
        """Which model to pick, and why."""
        ratio = max(self.UO, -self.UC) / min(self.UO, -self.UC) - 1.0
        small = 0.05 / self.Tg  # [pu/s] initial gate speed a 5 % step asks of a lag Tg
        why = [f"opening and closing rates differ by {100 * ratio:.0f} %" + (" (> 10 %): only HYGOV4 carries both (UO, UC)"
                                                                           if ratio > HYGOV4_RATIO else " (<= 10 %)")]
        if small > 0.5 * self.VELM:
            clip = {d: self.hygov4_clipped(d) for d in (0.05, -0.05)}
            clipped = [f"{100 * d:+.0f} % for {1e3 * t:.0f} ms" for d, t in clip.items() if t > 0]
            why.append(f"a 5 % step asks {small:.2f} pu/s of the lag, comparable with VELM {self.VELM:.2f} pu/s: HYGOV's limit on "
                       "the integrator ramps the desired gate before the Tg lag and slows small steps; HYGOV4's limits "
                       "act on the gate itself, as the servo's own rate does"
                       + (f" (they clip a {' and a '.join(clipped)})" if clipped else " (they do not clip a 5 % step)"))
        pick = "HYGOV4" if (ratio > HYGOV4_RATIO or small > 0.5 * self.VELM) else "HYGOV"
        return {"recommended": pick, "andes_models": list(ANDES_MODELS), "opening_closing_rate_difference": ratio,
                "why": "; ".join(why),
                "notes": ["ANDES 2.0 has HYGOV, HYGOVDB and HYGOV4; there is no IEEEG3.",
                          "In HYGOV, VELM limits the rate of the integrator (the desired gate), not the gate: the gate "
                          "follows it through the Tg lag, so VELM is reached one Tg into a long move.",
                          "In HYGOV4 the limits UO/UC act on the gate velocity; Tg is the gain of the gate integrator "
                          "inside the droop feedback, equal to the positioner's time constant only when that feedback "
                          "is unity (Rperm = 1 pu on the system base, Rtemp = 0); with droop the gate loop's time constant is "
                          "Tg/(Rperm + Rtemp) on the system base.",
                          "HYGOVDB's dead band (dbL/dbU) is on the speed input, not the gate: the servo's dead-zone steady "
                          "error has no place in these models (PSS/E HYGOV4's DB2 is ignored by ANDES)."]}

    def hygov4_clipped(self, step: float, dt: float = 1e-4) -> float:
        """How long [s] HYGOV4's gate-velocity limit (UO/UC) clips a set-point ``step`` [pu] of the bare positioner.

        The HYGOV4 gate loop with unity feedback (Rperm = 1 pu on Sb, Rtemp = 0): LAG' = (e - LAG)/Tp with
        e = step - gate change, gate' = clip(LAG/Tg, UC, UO) (ANDES 2.0, models/governor/hygov4.py), integrated here.
        """
        tp = max(self.dead_time or 0.0, 1e-3)
        lag = moved = 0.0
        clipped = 0.0
        for _ in range(int(10 * (self.Tg + tp) / dt)):
            lag += dt * ((step - moved) - lag) / tp
            want = lag / self.Tg
            rate = min(max(want, self.UC), self.UO)
            if rate != want:
                clipped += dt
            moved += dt * rate
        return clipped

    def servo(self) -> dict:
        """The measured figures, pu on the machine base (gate = stroke)."""
        L = self.stroke
        return {"Tg": self.Tg, "Tg_linear": self.Tg_linear, "dead_time": self.dead_time,
                "UO": self.UO, "UC": self.UC, "VELM": self.VELM,
                "UO_peak": self._best("opening", "peak_pu_per_s"), "UC_peak": -self._best("closing", "peak_pu_per_s"),
                "GMAX": self.GMAX, "GMIN": self.GMIN,
                "steady_error_pu": {k: v / L for k, v in self.steady_error.items()}}

    def andes(self, rating_mva: float | None = None, system_mva: float = SYSTEM_MVA,
              dispatch_mw: float | None = None) -> dict:
        """Every parameter of ``ss.add("HYGOV4", {...})`` and ``ss.add("HYGOV", {...})`` (ANDES 2.0) as a number
        on the machine base, for a bare positioner: the gate follows its set-point through the servo's own lag,
        dead time and rate limits. With the basis each number rests on.

        Parameters
        ----------
        rating_mva : float, optional
            Tn, the unit's rating [MVA]: the machine base (default: the system base, Tn = Sb).
        system_mva : float
            Sb, the study's system base [MVA] (default 100, PSS/E's and ANDES's).
        dispatch_mw : float, optional
            The unit's mechanical power at the operating point [MW], as the case dispatches it; At is chosen so
            that the gate starts at the operating point (default: Tn times the operating gate, At = 1).

        Returns
        -------
        dict
            ``HYGOV4`` and ``HYGOV`` (complete parameter dicts, ``Tn`` included), ``setpoint`` (per model: the
            ``paux0`` step per pu of gate, on Sb), ``gate_output`` (what ``GATE_y`` / ``LAG_y`` read per pu of gate),
            ``gate0`` (the operating gate, pu), ``basis`` (every choice in words) and ``scaling``.
        """
        s = self.servo()
        tn = float(system_mva if rating_mva is None else rating_mva)
        if not (tn > 0 and system_mva > 0):
            raise ValueError(f"rating {tn!r} MVA and system base {system_mva!r} MVA must be positive")
        k = tn / system_mva  # machine base -> system base, ANDES's Tn/Sb for power=True parameters
        g0 = self.point["position"] / self.stroke
        p0 = g0 if dispatch_mw is None else dispatch_mw / tn  # [pu on Tn]
        at = p0 / g0 if g0 > 0 else 1.0
        tp = max(s["dead_time"] or 0.0, 1e-3)
        turbine = {"Tw": 1.0, "At": at, "qNL": 0.0}
        hygov4 = {"Tn": tn, "Tg": s["Tg"], "Tp": tp, "UO": s["UO"], "UC": s["UC"], "PMAX": s["GMAX"], "PMIN": s["GMIN"],
                  "Rperm": k, "Rtemp": 0.0, "Tr": 1.0, "Dturb": 0.0, "Hdam": 1.0 / k, **turbine}
        hygov = {"Tn": tn, "R": k / DESIRED_GATE_TAU, "r": TEMPORARY_DROOP * k, "Tr": 1.0 / (TEMPORARY_DROOP * k),
                 "Tf": FILTER_TAU, "Tg": s["Tg"], "VELM": s["VELM"], "GMAX": s["GMAX"], "GMIN": s["GMIN"], "Dt": 0.0,
                 **turbine}
        basis = {
            "Tn": f"{tn:g} MVA, the machine base of every number here ({'the system base: no rating given' if rating_mva is None else 'the unit rating given'})",
            "Sb": f"{system_mva:g} MVA, the system base; ANDES scales power=True parameters by Tn/Sb = {k:g} and R, r, "
                  "Rperm, Rtemp by Sb/Tn",
            "servo": "Tg, Tp, UO, UC, VELM, PMAX/GMAX, PMIN/GMIN: the servo as measured (basis.sentences)",
            "Rperm": f"Tn/Sb = {k:g}: 1 pu on Sb, a unity gate loop whose time constant is Tg (HYGOV4's gate integrator is "
                     "fed on Sb while Rperm is converted)",
            "Rtemp": "0: no temporary droop, so Tr does nothing (1 s kept as a valid value)",
            "Hdam": f"Sb/Tn = {1.0 / k:g}: a head of 1 pu on Sb",
            "At": f"{at:.6g} = dispatch / (Tn x gate0) = {p0:.6g} / {g0:.6g}: the gate starts at the operating point "
                  f"{g0:.4f} pu ({self.point['position'] * 1e3:.1f} mm) when the case dispatches "
                  f"{p0 * tn:.6g} MW on this unit",
            "qNL": "0: the flow follows the gate (the unit's no-load flow is its own data: a power study sets it)",
            "Tw": "1 s: the water starting time does not move the gate (the unit's own value for a power study)",
            "Dturb": "0: no turbine damping (the unit's own data)",
            "HYGOV_R": f"Tn/(Sb x {DESIRED_GATE_TAU:g} s) = {k / DESIRED_GATE_TAU:g}: the desired gate follows the "
                       f"set-point within {DESIRED_GATE_TAU * 1e3:g} ms (1/R on Sb), so the gate moves with Tg and VELM",
            "HYGOV_r": f"{TEMPORARY_DROOP:g} x Tn/Sb: no proportional path; Tr = 1/r so that PSS/E's integrator gain "
                       "1/(r Tr) is 1 as ANDES's is",
            "HYGOV_Tf": f"{FILTER_TAU * 1e3:g} ms: the speed filter out of the way",
        }
        return {"HYGOV4": hygov4, "HYGOV": hygov,
                "setpoint": {"HYGOV4": k, "HYGOV": k / DESIRED_GATE_TAU,
                             "note": "paux0 per pu of gate (on Sb, the model's own gain R or Rperm times Tn/Sb): raise "
                                     "paux0 by this times the gate change [pu of stroke] to move the set-point"},
                "gate_output": {"per_pu_gate": k, "note": "GATE_y (HYGOV4) and LAG_y (HYGOV) read this per pu of gate"},
                "gate0": g0, "basis": basis,
                "scaling": "ANDES converts power=True parameters (GMAX, GMIN, VELM, UO, UC, PMAX, PMIN, qNL, Dt, Hdam) "
                           "from Tn (or the generator's Sn when Tn = 0, as after reading a .dyr) to the system base Sb by "
                           "Tn/Sb, and R, r, Rperm, Rtemp by Sb/Tn; the numbers here are given on Tn, once."}

    def dyr(self, bus: int = 1, machine: str = "1", rating_mva: float | None = None, system_mva: float = SYSTEM_MVA,
            dispatch_mw: float | None = None) -> str:
        """A PSS/E HYGOV record, every CON a number on the machine base (the bare positioner of :meth:`andes`).

        A .dyr carries no Tn: ANDES takes the generator's MBASE (Sn), which must be ``rating_mva``.
        """
        a = self.andes(rating_mva, system_mva, dispatch_mw)["HYGOV"]
        values = dict(a, Dturb=a["Dt"])
        nums = " ".join(f"{values[k]:.6g}" for k in HYGOV_DYR_ORDER)
        tn = a["Tn"]
        return (f"{bus} 'HYGOV' '{machine}' {nums} /  govcheck {self.name}: bare gate positioner on MBASE {tn:g} MVA, "
                f"SBASE {system_mva:g} MVA (Tg VELM GMAX GMIN the servo; R r Tr Tf make the governor transparent; "
                "Tw At Dturb qNL a turbine whose flow follows the gate)")

    def to_dict(self) -> dict:
        """Everything as JSON: the HYGOV block (parameters, rate_limits, units) first, then the other forms."""
        s = self.servo()
        return jsonable({
            "model": "HYGOV",
            "parameters": {"Tg": s["Tg"], "VELM": s["VELM"], "GMAX": s["GMAX"], "GMIN": s["GMIN"]},
            "rate_limits": {"UO": s["UO"], "UC": s["UC"], "UO_peak": s["UO_peak"], "UC_peak": s["UC_peak"]},
            "units": {"Tg": "s", "VELM": "pu/s", "GMAX": "pu", "GMIN": "pu", "UO": "pu/s", "UC": "pu/s (negative: closing)",
                      "UO_peak": "pu/s", "UC_peak": "pu/s (negative: closing)"},
            "Tg_linear": s["Tg_linear"],
            "HYGOV4": self.andes(**self.study)["HYGOV4"],
            "ieee_pes_tr_2013": {"T_G": s["Tg"], "U_O": s["UO"], "U_C": s["UC"], "G_max": s["GMAX"], "G_min": s["GMIN"],
                                 "VELM": s["VELM"]},
            "andes": self.andes(**self.study),
            "psse_dyr": {"HYGOV": self.dyr(**self.study),
                         "basis": "the bare positioner of andes.HYGOV, on the machine base andes.basis names (a .dyr has no "
                                  "Tn: MBASE, the generator's rating, must be that Tn)"},
            "family": self.family,
            "conventions": self.conventions(),
            "left_out": self.left_out(),
            "basis": self.basis(),
        })

    def conventions(self) -> dict:
        """Per-unit and sign conventions."""
        return {"gate_pu": f"x / stroke (stroke {self.stroke * 1e3:.1f} mm; 0 closed, 1 fully open)",
                "base": "machine base: 1 pu gate = full stroke of this servo; set Tn (ANDES) / MBASE (PSS/E) to the unit's rating",
                "rates": "pu/s of stroke; UC negative (closing)",
                "Tg": "time constant after the dead time (the IEC 61362 metric: end of dead time to 63.2 %)",
                "peak": "UO_peak/UC_peak: the largest gate speed of the same moves (20 ms window), beside the 25-75 % rate"}

    def left_out(self) -> dict:
        """What the first-order-lag-with-rate-limits models do not carry."""
        L = self.stroke
        return {"dead_time": {"value": self.dead_time, "unit": "s",
                              "note": "mean dead time of the Tg steps; HYGOV has none; HYGOV4's Tp is set to it (a lag standing in for a delay)"},
                "dead_zone_steady_error": {"value": dict(self.steady_error), "unit": "m",
                                           "pu": {k: v / L for k, v in self.steady_error.items()},
                                           "note": "the compensated valve shuts inside this error band; no gate dead band in HYGOV/HYGOV4 as ANDES implements them"},
                "friction": "breakaway and Coulomb friction are inside the measured Tg (nonlinear steps), not modelled separately"}

    def basis(self) -> dict:
        """How every figure was measured (operating point, load, circuit, runs), with sentences for a report."""
        circuit = {True: "flow-control valves 2V2/2V3 in", False: "flow-control valves out", None: "as configured"}[self.flow_control]
        pt, x = self.point, self.point["position"]
        samples = [s["time_constant"] for s in self.steps]
        opens = [m for m in self.moves if m["direction"] == "opening"]
        closes = [m for m in self.moves if m["direction"] == "closing"]
        sl = self.stroke_load
        load_text = "the load curve" if sl == "curve" else ("no load" if sl is None else f"{sl / 1e3:.2f} kN")

        def rows(ms):
            return ", ".join(f"{100 * m['start_pu']:.0f} %: {m['rate_pu_per_s']:.3f} (peak {m['peak_pu_per_s']:.2f})" for m in ms)

        sentences = [
            f"Tg = {self.Tg:.3f} s: {self.Tg_source}, " + ", ".join(f"{100 * s['step']:+.0f} % {'-' if s['time_constant'] is None else format(s['time_constant'], '.3f')} s"
                                                                  for s in self.steps)
            + f" from rest at {x * 1e3:.1f} mm ({100 * x / self.stroke:.0f} %), load {pt['load'] if isinstance(pt['load'], str) else pt['load']}"
            + f" ({pt['load_force'] / 1e3:.2f} kN), {circuit}; dead time {1e3 * (self.dead_time or 0):.0f} ms subtracted.",
            f"UO = {self.UO:.3f} pu/s and UC = {self.UC:.3f} pu/s: the fastest 25-75 % rates of reference steps from rest to the far "
            f"end stop under {load_text}, {circuit}; openings from {rows(opens)}; closings from {rows(closes)} pu/s.",
            "For comparison, strokes from the end stops (a commissioning stroke-time test): "
            + ", ".join(f"{m['direction']} {m['stroke_time']:.2f} s ({m['rate_pu_per_s']:.3f} pu/s, peak {m['peak_pu_per_s']:.2f})" for m in self.end_stop) + ".",
        ]
        return {"Tg_point": {"position": x, "load": pt["load"], "load_force": pt["load_force"]}, "Tg_steps": [s["step"] for s in self.steps],
                "Tg_nonlinear_samples": samples, "Tg_source": self.Tg_source, "steps": self.steps,
                "circuit": circuit, "flow_control": self.flow_control, "moves_load": sl, "moves": self.moves,
                "end_stop_strokes": self.end_stop, "sentences": sentences}

    def to_json(self) -> str:
        """The parameters as a JSON document."""
        return json.dumps(self.to_dict(), indent=2)

    def table(self) -> str:
        """Plain parameter table (what the CLI prints and docs/linear.md section 7 shows)."""
        s = self.servo()
        rows = [("Tg", f"{s['Tg']:.3f}", "s", "gate servo time constant (HYGOV, HYGOV4), dead time subtracted"),
                ("Tg (linear)", "-" if s["Tg_linear"] is None else f"{s['Tg_linear']:.3f}", "s", "same point, linear model"),
                ("dead time", "-" if s["dead_time"] is None else f"{s['dead_time']:.3f}", "s", "left out of HYGOV; HYGOV4 Tp"),
                ("VELM", f"{s['VELM']:.4f}", "pu/s", "HYGOV velocity limit (faster direction; limits the integrator)"),
                ("UO", f"{s['UO']:.4f}", "pu/s", f"opening rate 25-75 % from rest (peak {s['UO_peak']:.3f})"),
                ("UC", f"{s['UC']:.4f}", "pu/s", f"closing rate 25-75 % from rest (peak {s['UC_peak']:.3f})"),
                ("GMAX", f"{s['GMAX']:.2f}", "pu", "maximum gate (stroke end)"),
                ("GMIN", f"{s['GMIN']:.2f}", "pu", "minimum gate (closed)"),
                ("steady error", f"{max(s['steady_error_pu'].values()):.4f}", "pu", "dead-zone stall band, left out")]
        w = max(len(r[0]) for r in rows)
        lines = [f"{n:<{w}}  {v:>8} {u:<5} {m}" for n, v, u, m in rows]
        lines.append(f"model: {self.family['recommended']} ({self.family['why']})")
        lines.append("PSS/E: " + self.dyr(**self.study))
        return "\n".join(lines)

"""Sizing a gate servo from its duty and requirement file: cylinders, valve, throttles, controller.

The rules (docs/sizing.md; each constant is our choice, named with what it reproduces):

- **Cylinders** (ISO 15552 bores with their standard rods): the side area A must carry the
  largest force at ``LOAD_RATIO`` of the supply's gauge pressure, A >= F_max / (0.75 (p_s - p_atm)).
  A tandem pair offers A_cap + A_rod on both sides (equal forces and speeds both ways, the plant
  paper's arrangement), one cylinder min(A_cap, A_rod); the smallest area that suffices is chosen.
  Plant A's 12 kN on 2 x 125/32 mm at 7 bar gauge works at a ratio of 0.72.
- **Valve** (ISO 6358 nominal flow, 6 bar gauge inlet, 1 bar drop): its choked flow at supply
  must be ``VALVE_AUTHORITY`` = 3 times the mass flow that fills the driving side at the stroke
  speed v = L / T: C p_s rho_0 sqrt(T_0/T_s) >= 3 rho_s A v (the throttle, not the valve, then
  sets the stroke time and the controller keeps authority); the next standard rating up. Plant
  A's 700 NL/min valve is 3.1 times its 5 s stroke flow.
- **Throttles** (meter-out, in series with the valve's exhaust path, ISO 6358 series rule): the
  steady choked exhaust of the stroke speed, C_eq = A v / (R T rho_0), then refined by simulating
  the full stroke at the requirement's set-up load until its 25-75 % time is the target (secant).
- **Controller**: the valve opening beyond the dead zone gives a no-load speed gain
  K_v = v_choke / (u_sat - dz); K_P = 1 / (tau K_v) for the middle tau of the time-constant window
  (a type-1 loop: the piston integrates the flow); K_I = K_P / 1000 s (trims a load offset only);
  K_D = K_P / omega_n with the pneumatic natural frequency omega_n = sqrt(2 gamma p_s A^2 / (V M))
  at mid stroke; dead-zone compensation at the valve's dead zones with a smoothing width of 2/3
  of the smaller one (seed 000 eq. 3; the paper's 0.4 V of 0.61 V).
"""

from __future__ import annotations

import math
from dataclasses import replace as dc_replace

from compliance.physics.valve_rating import conductance_of_rating, rating_of_conductance

__all__ = ["ISO_15552", "MAX_BORE_STEPS", "STANDARD_RATINGS", "size_and_check", "size_cylinders", "size_servo", "size_valve",
           "time_constant_target"]

ISO_15552 = ((0.032, 0.012), (0.040, 0.016), (0.050, 0.020), (0.063, 0.020), (0.080, 0.025), (0.100, 0.025),
             (0.125, 0.032), (0.160, 0.040), (0.200, 0.040), (0.250, 0.050), (0.320, 0.063))  # bore, rod [m]
STANDARD_RATINGS = (100.0, 350.0, 700.0, 1400.0, 2000.0)  # NL/min of 5/3 proportional valves
LOAD_RATIO = 0.75
VALVE_AUTHORITY = 3.0
TAU_DEFAULT = 0.175  # s, middle of IEC 61362's 0.10-0.25 s when the requirement file gives no window
INTEGRAL_TIME = 1000.0  # s


def _areas(bore: float, rod: float) -> tuple[float, float]:
    cap = math.pi * bore * bore / 4.0
    return cap, cap - math.pi * rod * rod / 4.0


def size_cylinders(force: float, supply: float, atmosphere: float, min_area: float = 0.0, count: int | None = None) -> dict:
    """Count, bore, rod [m], side area [m^2] and load ratio for ``force`` [N] at ``supply`` [Pa abs].

    ``min_area`` [m^2]: take a side area above it (the next size up when a check asks for a lower load share);
    ``count``: keep that arrangement (2 = the tandem pair, 1 = one cylinder).
    """
    need = max(force / (LOAD_RATIO * (supply - atmosphere)), min_area)
    options = []
    for bore, rod in ISO_15552:
        cap, ann = _areas(bore, rod)
        options += [(cap + ann, 0, 2, bore, rod), (min(cap, ann), 1, 1, bore, rod)]  # tandem first on a tie
    ok = sorted(o for o in options if o[0] >= need and o[0] > min_area and (count is None or o[2] == count))
    if not ok:
        raise ValueError(f"no ISO 15552 pair carries {force:.0f} N at {supply/1e5:.1f} bar abs")
    area, _, count, bore, rod = ok[0]
    return {"count": count, "arrangement": "tandem" if count == 2 else "single", "bore": bore, "rod": rod,
            "area": area, "area_needed": need, "load_ratio": force / (area * (supply - atmosphere))}


def size_valve(area: float, speed: float, supply: float, temperature: float, atmosphere: float, b: float,
               rho0: float = 1.204, t0: float = 293.15, r_gas: float = 287.0) -> dict:
    """Needed and chosen nominal flow [NL/min] for ``speed`` [m/s] of a side of ``area`` [m^2]."""
    fill = supply / (r_gas * temperature) * area * speed  # kg/s into the driving side at supply density
    c_need = VALVE_AUTHORITY * fill / (supply * rho0 * math.sqrt(t0 / temperature))
    need = rating_of_conductance(c_need, atmosphere, b)
    chosen = next((r for r in STANDARD_RATINGS if r >= need), STANDARD_RATINGS[-1])
    return {"rating_needed": need, "rating": chosen, "fill_flow": fill,
            "conductance": conductance_of_rating(chosen, atmosphere, b)}


def _steady_throttle(area, speed, c_valve, r_gas, temperature, rho0):
    """Meter-out conductance whose choked series path passes the stroke's exhaust: C_eq = A v / (R T rho_0)."""
    c_eq = area * speed / (r_gas * temperature * rho0)
    if c_eq >= c_valve:
        return 0.0  # the valve alone is the limit: no throttle
    return 1.0 / math.sqrt(1.0 / c_eq ** 2 - 1.0 / c_valve ** 2)


def _controller(cfg, area, c_valve, tau) -> dict:
    p = cfg.params
    ps, ts = p["air.supply_pressure"], p["air.supply_temperature"]
    choke = c_valve * ps * p["air.reference_density"] * math.sqrt(p["air.reference_temperature"] / ts)
    v_choke = choke * p["air.gas_constant"] * ts / (ps * area)
    dz = 0.5 * (p["valve.dead_zone_positive"] + p["valve.dead_zone_negative"])
    kv = v_choke / (p["valve.saturation_voltage"] - dz)
    kp = 1.0 / (tau * kv)
    volume = area * 0.5 * p["cylinder.stroke"] + 2.0 * p["cylinder.dead_volume"]
    omega = math.sqrt(2.0 * p["air.heat_capacity_ratio"] * ps * area ** 2 / (volume * p["cylinder.moving_mass"]))
    width = 2.0 / 3.0 * min(p["valve.dead_zone_positive"], p["valve.dead_zone_negative"])
    return {"controller.kp": kp, "controller.ki": kp / INTEGRAL_TIME, "controller.kd": kp / omega,
            "controller.compensation_dead_zone_positive": p["valve.dead_zone_positive"],
            "controller.compensation_dead_zone_negative": p["valve.dead_zone_negative"],
            "controller.compensation_width": width, "_speed_gain": kv, "_omega": omega}


def time_constant_target(reqset) -> float:
    """Middle of the requirement file's time-constant window [s] (TAU_DEFAULT when it has none)."""
    for r in reqset.requirements:
        if r.metric == "time_constant" and r.enabled and r.limit is not None and len(r.limit) == 2:
            lo, hi = r.resolved_limit(1.0)
            return 0.5 * (lo + hi)
    return TAU_DEFAULT


def size_servo(duty, template, tau: float | None = None, min_area: float = 0.0, count: int | None = None) -> tuple:
    """(sized configuration, sizing record) for ``duty`` on ``template`` (steady throttle rule).

    The throttles are the steady first guess (:func:`compliance.sweep.sizing.throttle_tuning.tune_throttles`
    refines them by simulation, as plant A's were derived); ``govcheck size`` then sets the governor
    (``sizing.governor_design``). ``min_area`` [m^2]: cylinders with a larger side area than this.
    """
    atm = template.params["air.atmospheric_pressure"]
    cyl = size_cylinders(duty.max_force, duty.supply_pressure, atm, min_area, count)
    times = [t for t in (duty.opening_time, duty.closing_time) if t]
    speed = duty.stroke / min(times) if times else duty.stroke / 5.0
    ts = template.params["air.supply_temperature"]
    valve = size_valve(cyl["area"], speed, duty.supply_pressure, ts, atm, template.params["valve.critical_pressure_ratio"])
    params = {"cylinder.stroke": duty.stroke, "cylinder.piston_diameter": cyl["bore"], "cylinder.rod_diameter": cyl["rod"],
              "air.supply_pressure": duty.supply_pressure, "valve.sonic_conductance": valve["conductance"],
              "load.nominal_force": duty.max_force}
    for key, t in (("flow_control.opening_conductance", duty.opening_time), ("flow_control.closing_conductance", duty.closing_time)):
        params[key] = _steady_throttle(cyl["area"], duty.stroke / (t or 5.0), valve["conductance"],
                                       template.params["air.gas_constant"], ts, template.params["air.reference_density"])
    cfg = template.replace(params=params, options={"cylinder.arrangement": cyl["arrangement"]}, name=duty.name,
                           provenance={"sizing": f"govcheck size from {duty.path}"})
    ctl = _controller(cfg, cyl["area"], valve["conductance"], tau or TAU_DEFAULT)
    cfg = cfg.replace(params={k: v for k, v in ctl.items() if not k.startswith("_")})
    cfg = dc_replace(cfg, load_curve=(duty.force_position, duty.force))
    record = {"cylinders": cyl, "valve": valve, "stroke_speed": speed, "tau_target": tau or TAU_DEFAULT,
              "controller": ctl, "throttles_steady": {k: params[k] for k in params if k.startswith("flow_control.")}}
    return cfg, record


MAX_BORE_STEPS = 2  # larger cylinder pairs tried when the proposal's check fails (our choice)


def size_and_check(duty, template, reqset, *, workers=None, progress=False) -> tuple:
    """Size, set the governor, check, and step the cylinders up until the proposal passes.

    The governor design (``sizing.governor_design.design_and_check``) sets the rate limiter, the throttles
    and the controller on the sized hardware and checks the full campaign with the file's readings. What it
    cannot meet on a pair of cylinders (the time constant spreading wider than its window, the gate lagging
    the limiter under load, the tracking error at the rated load) grows with the load's share of the
    cylinders' force, so the next ISO 15552 size up in the same arrangement is sized (valve resized for it)
    and designed again, up to ``MAX_BORE_STEPS`` times.

    Returns
    -------
    tuple
        (configuration, sizing record of the last pair, results of its check, rounds): ``rounds`` has one
        entry per pair tried (bore, load share, status, failing requirements, what the design could not meet).
    """
    from compliance.requirements.verdict import Overall
    from compliance.sweep.sizing.governor_design import design_and_check, mandatory_uncertain

    tau = time_constant_target(reqset)
    rounds, min_area, count = [], 0.0, None
    for _ in range(MAX_BORE_STEPS + 1):
        cfg, rec = size_servo(duty, template, tau, min_area, count)
        cyl = rec["cylinders"]
        cfg, design, results = design_and_check(cfg, reqset, workers=workers, progress=progress)
        rec["design"] = design
        rounds.append({"bore": cyl["bore"], "rod": cyl["rod"], "count": cyl["count"], "load_ratio": cyl["load_ratio"],
                       "valve_rating": rec["valve"]["rating"], "status": results["summary"]["status"],
                       "failed_mandatory": results["summary"]["failed_mandatory"] + mandatory_uncertain(results),
                       "cannot": design.get("cannot")})
        if results["summary"]["status"] == Overall.PASS:
            break
        min_area, count = cyl["area"], cyl["count"]  # the next pair up, same arrangement
        try:
            size_cylinders(duty.max_force, duty.supply_pressure, template.params["air.atmospheric_pressure"], min_area, count)
        except ValueError:
            break
    return cfg, rec, results, rounds

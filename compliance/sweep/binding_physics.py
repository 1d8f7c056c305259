"""Why the binding requirement binds, physically, when no candidate of the space passes.

The closest candidate's binding requirement is explained by the physics its metric answers to,
with the numbers of the configuration and the requirement file:

- a time-constant window and a peak-speed limit on the same step size: a first-order answer
  x(t) = s (1 - exp(-t/tau)) starts at s/tau, so tau <= tau_max means a peak speed >= s/tau_max;
  a rate-limited answer reaches 63.2 % of s no sooner than 0.632 s / v_max (requirement-set
  arithmetic, not a property of the plant);
- the opening/closing time or time constant against the valve's choked flow: the fastest the
  valve can fill a chamber at supply pressure, v = C p_s rho_0 sqrt(T_0/T_s) R T_s / (p_s A)
  = C rho_0 R sqrt(T_0 T_s) / A (seed 000 eq. 1 with w = 1, isothermal chamber at supply pressure);
- the peak speed of a full stroke from an end stop: the end-stop surge (the exhausting chamber
  starts at supply pressure; the gate breaks away with that stored pressure difference);
- tracking, positioning and dead band: the valve dead zone and stick-slip friction.
"""

from __future__ import annotations

__all__ = ["choked_speed", "conflict_text", "explain", "explain_closest", "step_conflict"]

SPEED_METRICS = ("max_speed", "max_opening_speed", "max_closing_speed")


def choked_speed(cfg, conductance: float | None = None) -> float:
    """Piston speed [m/s] when the valve's choked flow fills the cap-side chambers at supply pressure."""
    p = cfg.params
    c = conductance if conductance is not None else p["valve.sonic_conductance"]
    tandem = cfg.options["cylinder.arrangement"] == "tandem"
    area = cfg.piston_area + cfg.rod_side_area if tandem else cfg.piston_area  # tandem side A: cap of one + rod of the other
    q = c * p["air.supply_pressure"] * p["air.reference_density"] * (p["air.reference_temperature"] / p["air.supply_temperature"]) ** 0.5
    return q * p["air.gas_constant"] * p["air.supply_temperature"] / (p["air.supply_pressure"] * area)


def step_conflict(reqset, stroke: float) -> list[dict]:
    """Step procedures judged both by a time-constant window and by a peak-speed limit, with the arithmetic."""
    out = []
    for tc in (r for r in reqset.requirements if r.metric == "time_constant" and r.enabled and r.limit and r.source != "linear"):
        tau_max = tc.resolved_limit(stroke)[-1]
        for sp in (r for r in reqset.requirements if r.metric in SPEED_METRICS and r.enabled and r.limit):
            v_max = sp.resolved_limit(stroke)[-1]
            for proc in sorted(set(tc.procedures) & set(sp.procedures)):
                size = reqset.procedures[proc].settings.get("size")
                if size is None:
                    continue
                s = size.resolve(stroke)
                out.append({"time_constant": tc.id, "speed": sp.id, "procedure": proc, "step": s, "tau_max": tau_max,
                            "same_points": sorted(set(tc.operating_points) & set(sp.operating_points)),
                            "v_max": v_max, "first_order_peak": s / tau_max, "ramp_tau_min": 0.632 * s / v_max,
                            "first_order_conflict": s / tau_max >= v_max, "any_servo_conflict": 0.632 * s / v_max > tau_max})
    return out


def conflict_text(c: dict) -> str:
    """The arithmetic of a time-constant window that no rate-limited servo can meet under a speed limit."""
    where = ("at the same operating points" if c["same_points"] else
             "judged at different operating points, so only a servo at least "
             f"{c['ramp_tau_min'] / c['tau_max']:.1f} times faster there than where the speed is judged escapes it")
    return (f"on {c['procedure']} ({c['step']*1e3:.1f} mm steps) {c['time_constant']} asks "
            f"tau <= {c['tau_max']:.3f} s and {c['speed']} a peak speed <= {c['v_max']*1e3:.1f} mm/s; moving no faster than that, "
            f"the gate reaches 63.2 % of the step after {c['ramp_tau_min']:.3f} s at the earliest "
            f"(0.632 x {c['step']*1e3:.1f} mm / {c['v_max']*1e3:.1f} mm/s), and a first-order answer within the window "
            f"starts at >= {c['first_order_peak']*1e3:.1f} mm/s ({where}).")


def explain_closest(closest: dict, cfg, reqset, tried_limiter: bool) -> str:
    """Why the closest candidate fails: a conflict of the requirement set it fails first, else its binding physics."""
    failing = set(closest.get("failed_mandatory") or ())
    L = cfg.params["cylinder.stroke"]
    hard = [c for c in step_conflict(reqset, L) if c["any_servo_conflict"] and {c["time_constant"], c["speed"]} & failing]
    text = explain(closest.get("binding"), closest.get("binding_where"), cfg, reqset, tried_limiter)
    if hard:
        lead = "No servo can pass both: " if hard[0]["same_points"] else "The requirement set works against any pass: "
        rest = set(closest.get("failed_mandatory") or ()) - {hard[0]["time_constant"], hard[0]["speed"]}
        binding_in_conflict = closest.get("binding") in (hard[0]["time_constant"], hard[0]["speed"])
        tail = "" if binding_in_conflict and not rest else " Besides, " + text
        return lead + conflict_text(hard[0]) + tail
    return text


def explain(rid: str | None, where: str | None, cfg, reqset, tried_limiter: bool) -> str:
    """One paragraph: why requirement ``rid`` (judged at run ``where``) binds, with the numbers."""
    if rid is None:
        return "no mandatory requirement could be judged on any candidate (every run failed or was not evaluated)."
    req = next((r for r in reqset.requirements if r.id == rid), None)
    if req is None:
        return f"{rid} binds."
    L = cfg.params["cylinder.stroke"]
    proc = (where or "").split("@")[0]
    if req.metric in SPEED_METRICS:
        conflicts = [c for c in step_conflict(reqset, L) if c["speed"] == rid and (not proc or c["procedure"] == proc)]
        if conflicts:
            c = conflicts[0]
            return (f"{rid} binds through a conflict in the requirement set: on {c['procedure']} ({c['step']*1e3:.1f} mm steps) "
                    f"{c['time_constant']} asks tau <= {c['tau_max']:.3f} s, so a first-order answer starts at "
                    f"s/tau >= {c['first_order_peak']*1e3:.1f} mm/s against the {c['v_max']*1e3:.1f} mm/s of {rid}; "
                    f"only a rate-limited answer can meet both (it reaches 63.2 % after {c['ramp_tau_min']:.3f} s at best).")
        if proc and reqset.procedures.get(proc) is not None and reqset.procedures[proc].kind == "full_stroke":
            lim = (" The set-point rate limiter with its ramp hold was in the space too: it trades the surge against the "
                   "stroke time (a small lead holds the gate back at breakaway and slows the stroke)." if tried_limiter else "")
            return (f"{rid} binds at the start of a full stroke from an end stop ({where}): the exhausting chamber starts at "
                    f"supply pressure ({cfg.params['air.supply_pressure']/1e5:.1f} bar abs) and the filling one near "
                    f"atmosphere; the gate is held until their forces cross and then breaks away with the stored pressure "
                    f"difference - the end-stop surge. Throttles and gains act after it.{lim} The hardware that acts on it "
                    "(an exhaust back-pressure valve, cushioned cylinders) is not modelled (catalogue: not_modelled).")
    if req.metric in ("opening_time", "closing_time", "time_constant"):
        v_c = choked_speed(cfg)
        need = L / req.resolved_limit(L)[-1] if req.metric != "time_constant" else None
        tail = (f"; a full stroke in {req.resolved_limit(L)[-1]:.2f} s needs {need*1e3:.1f} mm/s" if need else "")
        return (f"{rid} binds ({where}): the valve's choked flow fills the drive side at supply pressure at most as fast as "
                f"{v_c*1e3:.0f} mm/s of piston speed (C = {cfg.params['valve.sonic_conductance']*1e8:.2f} dm^3/(s*bar))"
                f"{tail}; below that, static friction and the pressure build-up before breakaway set the answer.")
    if req.metric in ("tracking_max_error", "max_positioning_error", "dead_band"):
        return (f"{rid} binds ({where}): inside the valve dead zone ({cfg.params['valve.dead_zone_positive']:.2f} / "
                f"{cfg.params['valve.dead_zone_negative']:.2f} V) no air flows, and the gate sticks until the pressure "
                f"difference overcomes static friction ({cfg.params['friction.static_force']:.0f} N per cylinder): the "
                "error builds up to the stall band before the gate moves (stick-slip).")
    return f"{rid} binds ({where}) on {req.metric}."

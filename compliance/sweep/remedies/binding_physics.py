"""Why the binding requirement binds, physically, when no candidate of the space passes.

The closest candidate's binding requirement is explained by the physics its metric answers to,
with the numbers of the configuration and the requirement file:

- limits of the requirement set that work against each other (a time-constant window against a
  speed limit on the same steps, or against the stroke rate limit on full strokes): the findings of
  ``requirements.consistency``, the one place that arithmetic lives, not a property of the plant;
- the opening/closing time or time constant against the valve's choked flow: the fastest the
  valve can fill a chamber at supply pressure, v = C p_s rho_0 sqrt(T_0/T_s) R T_s / (p_s A)
  = C rho_0 R sqrt(T_0 T_s) / A (seed 000 eq. 1 with w = 1, isothermal chamber at supply pressure);
- the peak speed of a full stroke from an end stop: the end-stop surge (the exhausting chamber
  starts at supply pressure; the gate breaks away with that stored pressure difference);
- tracking, positioning and dead band: the valve dead zone and stick-slip friction.
"""

from __future__ import annotations

from compliance.requirements.consistency import CONFLICT, RATE_SPLIT, TENSION, consistency_findings

__all__ = ["choked_speed", "explain", "explain_closest", "set_findings"]

SPEED_METRICS = ("max_speed", "max_opening_speed", "max_closing_speed")


def choked_speed(cfg, conductance: float | None = None) -> float:
    """Piston speed [m/s] when the valve's choked flow fills the cap-side chambers at supply pressure."""
    p = cfg.params
    c = conductance if conductance is not None else p["valve.sonic_conductance"]
    tandem = cfg.options["cylinder.arrangement"] == "tandem"
    area = cfg.piston_area + cfg.rod_side_area if tandem else cfg.piston_area  # tandem side A: cap of one + rod of the other
    q = c * p["air.supply_pressure"] * p["air.reference_density"] * (p["air.reference_temperature"] / p["air.supply_temperature"]) ** 0.5
    return q * p["air.gas_constant"] * p["air.supply_temperature"] / (p["air.supply_pressure"] * area)


def set_findings(reqset, stroke: float, rids) -> list[dict]:
    """Findings of the requirement set's consistency check (``requirements.consistency``) that involve ``rids``,
    the limits no servo can meet together first, then those that only a split of the rate limiting can meet."""
    order = {CONFLICT: 0, RATE_SPLIT: 1, TENSION: 2}
    found = [f for f in consistency_findings(reqset, stroke) if f["kind"] in order and set(f["requirements"]) & set(rids)]
    return sorted(found, key=lambda f: (order[f["kind"]], not f["mandatory"]))


def explain_closest(closest: dict, cfg, reqset, tried_limiter: bool) -> str:
    """Why the closest candidate fails: a finding of the requirement set on what it fails, then its binding physics."""
    failing = list(closest.get("failed_mandatory") or ())
    text = explain(closest.get("binding"), closest.get("binding_where"), cfg, reqset, tried_limiter)
    text += _by_construction(closest)
    found = set_findings(reqset, cfg.params["cylinder.stroke"], failing)
    if not found:
        return text
    f = found[0]
    lead = {CONFLICT: "No servo can pass both: ", TENSION: "The requirement set works against any pass: ",
            RATE_SPLIT: "The requirement set asks for two speeds: "}[f["kind"]]
    return lead + f["text"] + ". Besides, " + text


def _by_construction(closest: dict) -> str:
    """The failing mandatory requirements that pass only by construction: the model cannot evidence them."""
    bc = closest.get("by_construction") or []
    if not bc:
        return ""
    return (f" {', '.join(bc)} pass only by construction in the closest candidate (the model lacks the physics that could make "
            "them fail, or a parameter was derived to give them): no setting or modelled hardware turns them into evidence; "
            "model the missing effect or measure them.")


def _step_size(reqset, proc: str, stroke: float) -> float | None:
    """Step size [m] of a steps procedure, None for any other."""
    p = reqset.procedures.get(proc)
    return p.settings["size"].resolve(stroke) if p is not None and p.kind == "steps" else None


def _limited_steps(rid, where, cfg, req, h, stroke) -> str:
    """A time constant held back by the set-point rate limiter: the gate follows the ramp at best."""
    rate = min(cfg.params["controller.setpoint_opening_rate"], cfg.params["controller.setpoint_closing_rate"])
    tau_max = req.resolved_limit(stroke)[-1]
    return (f"{rid} binds ({where}): the set-point rate limiter ramps this {h*1e3:.1f} mm step at "
            f"{rate*1e3:.1f} mm/s, so the gate reaches 63.2 % of it no sooner than 0.632 x {h*1e3:.1f} mm / "
            f"{rate*1e3:.1f} mm/s = {0.632*h/rate:.3f} s (window <= {tau_max:.3g} s): the limiter that holds the strokes to "
            "their rate slows the steps as much (pid_controller, set-point rate limiter).")


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
        found = [f for f in set_findings(reqset, L, [rid]) if f["procedure"] == proc]
        if found:
            return f"{rid} binds through a finding of the requirement set: {found[0]['text']}."
        if proc and reqset.procedures.get(proc) is not None and reqset.procedures[proc].kind == "full_stroke":
            lim = (" The set-point rate limiter with its ramp hold was in the space too: it trades the surge against the "
                   "stroke time (a small lead holds the gate back at breakaway and slows the stroke)." if tried_limiter else "")
            return (f"{rid} binds at the start of a full stroke from an end stop ({where}): the exhausting chamber starts at "
                    f"supply pressure ({cfg.params['air.supply_pressure']/1e5:.1f} bar abs) and the filling one near "
                    f"atmosphere; the gate is held until their forces cross and then breaks away with the stored pressure "
                    f"difference - the end-stop surge. Throttles and gains act after it.{lim} The hardware that acts on it "
                    "(an exhaust back-pressure valve, cushioned cylinders) is not modelled (catalogue: not_modelled).")
    point = reqset.operating_points.get((where or "").split("@")[-1])
    through_limiter = point is None or point.setpoint_limiter is not False  # a tc point may inject downstream of it
    if req.metric == "time_constant" and cfg.setpoint_rate_limited and through_limiter and _step_size(reqset, proc, L):
        return _limited_steps(rid, where, cfg, req, _step_size(reqset, proc, L), L)
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

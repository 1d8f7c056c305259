"""Which procedure x operating point of a requirement file a measured case stands for, and how it departs from it.

A case maps to a procedure by kind and size (a step of the procedure's size; a full stroke in one
of its directions; a sinusoid of its amplitude and frequency), and to an operating point by
position and load (a full stroke starts at an end, so its load alone). The circuit (flow-control
valves in or open) is compared too: a case run with another circuit than the point's still maps,
and the difference is a departure the row states. Where the test as run differs from the
procedure (a hold with the loop open, a staircase for a triangle, fewer periods) the departure is
stated the same way.
"""

from __future__ import annotations

from compliance.acceptance.site.stated import PROCEDURE_KIND

__all__ = ["LOAD_TOLERANCE", "POSITION_TOLERANCE", "circuit_text", "point_match", "procedure_match"]

POSITION_TOLERANCE = 0.02  # share of the stroke: a test within 3.2 mm of a point's position (160 mm) runs at that point
LOAD_TOLERANCE = (0.05, 500.0)  # relative, absolute [N]: a test's load within the larger of the two is the point's load
SIZE_TOLERANCE = 0.1  # share of the procedure's step size (and of a sinusoid's amplitude and frequency)
_KINDS = set(PROCEDURE_KIND.values())


def circuit_text(flow_control: bool | None) -> str:
    """The circuit in words."""
    return {True: "flow-control valves in (as commissioned)", False: "flow-control valves open",
            None: "flow-control valves not stated"}[flow_control]


def _point_load(op, cfg):
    if op.load is None:
        return 0.0
    if op.load == "nominal":
        return cfg.p("load.nominal_force")
    return op.load


def point_match(op, case, cfg) -> tuple[bool, bool, list]:
    """Whether ``case`` ran at operating point ``op`` (position and load), whether the circuit is the point's too, and the departures.

    Returns
    -------
    (bool, bool, list of str)
    """
    stroke = cfg.p("cylinder.stroke")
    c = case.conditions
    load, want = c.get("load"), _point_load(op, cfg)
    if (want == "curve") != (load == "curve"):
        return False, False, []
    if want != "curve":
        load = 0.0 if load is None else float(load)
        if abs(load - want) > max(LOAD_TOLERANCE[0] * abs(want), LOAD_TOLERANCE[1]):
            return False, False, []
    if case.kind != "full_stroke" and op.initial_position is not None:
        x = c.get("position")
        if x is None or abs(x - op.initial_position.resolve(stroke)) > POSITION_TOLERANCE * stroke:
            return False, False, []
    installed = cfg.flow_control_installed if op.flow_control is None else bool(op.flow_control)
    ran = c.get("flow_control")
    departures = []
    if ran is None:
        departures.append(f"circuit not stated in the sidecar; the point asks for {circuit_text(installed)}")
    elif ran != installed:
        departures.append(f"run with {circuit_text(ran)}; the point '{op.name}' asks for {circuit_text(installed)}")
    return True, ran == installed, departures


def _step_match(proc, case, stroke: float, listed) -> bool:
    size = proc.settings["size"].resolve(stroke)
    if abs(case.conditions.get("size", 0.0) - size) > SIZE_TOLERANCE * size:
        return False
    d, pattern = case.conditions.get("direction"), proc.settings.get("pattern", ["up", "down"])
    same = [p for p in listed if p.kind == "steps" and abs(p.settings["size"].resolve(stroke) - size) <= SIZE_TOLERANCE * size]
    if case.conditions.get("role") == "outward" and any(p.settings.get("pattern", ["up"])[0] == d for p in same):
        return pattern[0] == d  # a step away from the point: the procedure that starts with it
    sequences = [p for p in same if d in p.settings.get("pattern", []) and len(p.settings.get("pattern", [])) > 1]
    if sequences:
        return proc in sequences
    return d in pattern


def procedure_match(proc, case, cfg, listed) -> tuple[bool, list]:
    """Whether ``case`` is a run of procedure ``proc`` and how the test as run departs from it.

    ``listed`` are the procedures the requirement names (a step away from the operating point maps
    to the one that starts in its direction; a step back to a sequence that contains it).
    """
    if proc.kind not in _KINDS or case.kind != proc.kind:
        return False, []
    stroke = cfg.p("cylinder.stroke")
    s = proc.settings
    if proc.kind == "steps":
        return _step_match(proc, case, stroke, listed), list(case.departures)
    if proc.kind == "full_stroke":
        if not case.problem and case.conditions.get("direction") not in s.get("directions", ["opening", "closing"]):
            return False, []
        dep = list(case.departures)
        wanted = s.get("flow_control", True)
        if case.conditions.get("flow_control") is not None and case.conditions["flow_control"] != wanted:
            dep.append(f"the procedure strokes with {circuit_text(wanted)}")
        return True, dep
    if proc.kind == "sine":
        c = case.conditions
        amp, f = s["amplitude"].resolve(stroke), s["frequency"].value
        if c.get("amplitude") is None or abs(c["amplitude"] - amp) > SIZE_TOLERANCE * amp or \
                c.get("frequency") is None or abs(c["frequency"] - f) > SIZE_TOLERANCE * f:
            return False, []
        return True, list(case.departures)
    if proc.kind == "hold":
        dep = list(case.departures)
        if case.conditions.get("loop") == "open":
            dep.append("held with the positioner in manual and the valve at null (the servomotor drift test); the procedure "
                       "holds in closed loop: the drift is judged, the closed-loop figures are not measured by this test")
        return True, dep
    dep = list(case.departures) + [
        "a set-point staircase (the commissioning dead-band test, metrics.staircase) where the procedure runs a slow "
        "triangle; the dead band is read per leg after each reversal"]
    return True, dep

"""The linear analysis a compliance report carries: every operating point of the requirement set,
the stroke x load map, the linear/nonlinear cross-check and the HYGOV parameters."""

from __future__ import annotations

from compliance.model.config import PlantConfig
from compliance.errors import InputError


def linear_for_campaign(cfg: PlantConfig, reqset, *, with_map: bool = True) -> dict:
    """Build the ``linear`` entry of a results dict (schema ``govcheck-linear/1``, as ``govcheck linear --json``).

    Parameters
    ----------
    cfg : PlantConfig
        A PID-controlled plant (the state-feedback plant B has no closed-loop linear model here).
    reqset : RequirementSet
        Its operating points with an initial position are analysed (critical points).
    with_map : bool
        Include the stroke x load operating map (the slowest part, ~10-25 s).

    Returns
    -------
    dict
        ``{"schema", "analyses": [...], "map", "crosscheck", "governor", "notes"}``.
    """
    from compliance.files.jsonable import jsonable
    from compliance.linear.analysis import analyse
    from compliance.linear.maps import crosscheck, operating_map
    from compliance.linear.governor_model import governor_parameters
    from compliance.simulation.scenario import scenario_load

    out: dict = {"schema": "govcheck-linear/1", "analyses": [], "notes": []}
    if cfg.options["controller.type"] != "pid":
        out["notes"].append(f"linear closed-loop analysis covers PID plants; {cfg.name} uses "
                            f"controller.type = '{cfg.options['controller.type']}' (see docs/plant-b.md for its design model)")
        return out
    stroke = cfg.p("cylinder.stroke")
    seen = set()
    for op in reqset.operating_points.values():
        if op.initial_position is None:
            continue
        x = op.initial_position.resolve(stroke)
        load = scenario_load(cfg, op)
        key = (round(x, 6), load if isinstance(load, str) else (None if load is None else round(float(load), 3)), op.flow_control)
        if key in seen or not 0.0 <= x <= stroke:
            continue
        seen.add(key)
        try:
            a = analyse(cfg, x, load, flow_control=op.flow_control)
        except InputError as exc:
            out["notes"].append(f"operating point '{op.name}': not linearised ({exc})")
            continue
        d = a.to_dict()
        d["requirement_operating_point"] = op.name
        out["analyses"].append(d)
    if with_map:
        out["map"] = operating_map(cfg).to_dict()
    out["crosscheck"] = jsonable(crosscheck(cfg))
    out["governor"] = governor_parameters(cfg).to_dict()
    return jsonable(out)

"""The linear analysis a compliance report carries: every operating point of the requirement set,
the stroke x load map, the linear/nonlinear cross-check and the HYGOV parameters."""

from __future__ import annotations

from compliance.model.config import PlantConfig
from compliance.errors import InputError
from compliance.plants import kind_of


def linear_for_campaign(cfg: PlantConfig, reqset, *, with_map: bool = True, workers: int | None = None) -> dict:
    """Build the ``linear`` entry of a results dict (schema ``govcheck-linear/1``, as ``govcheck linear --json``).

    Parameters
    ----------
    cfg : PlantConfig
        A plant whose kind has the closed-loop linear model (``PlantKind.linear_support``: the PID servo);
        any other gets a note and no analyses.
    reqset : RequirementSet
        Its operating points with an initial position are analysed (critical points).
    with_map : bool
        Include the stroke x load operating map (the slowest part).
    workers : int, optional
        Processes (default: the available cores). The operating points, the map cells, the
        cross-check points and the HYGOV fit are independent and run in parallel.

    Returns
    -------
    dict
        ``{"schema", "analyses": [...], "map", "crosscheck", "governor", "notes"}``.
    """
    from compliance.files.jsonable import jsonable
    from compliance.simulation.scenario import scenario_load

    out: dict = {"schema": "govcheck-linear/1", "analyses": [], "notes": []}
    why = kind_of(cfg).linear_support(cfg)
    if why is not None:  # a plant kind without govcheck's closed-loop linear model
        out["notes"].append(f"{cfg.name}: {why}")
        return out
    stroke = cfg.p("cylinder.stroke")
    seen, tasks = set(), []
    for op in reqset.operating_points.values():
        if op.initial_position is None:
            continue
        x = op.initial_position.resolve(stroke)
        load = scenario_load(cfg, op)
        key = (round(x, 6), load if isinstance(load, str) else (None if load is None else round(float(load), 3)), op.flow_control)
        if key in seen or not 0.0 <= x <= stroke:
            continue
        seen.add(key)
        tasks.append(("point", op.name, x, load, op.flow_control))
    # independent pieces, slowest first (the cross-check simulates), spread over the cores
    tasks = [("crosscheck", x, ld) for x, ld in _crosscheck_points(stroke)] + [("governor",)] + tasks
    positions, loads = _map_grid(cfg) if with_map else ([], [])
    tasks += [("cell", i, j, ld, x) for i, ld in enumerate(loads) for j, x in enumerate(positions)]
    results = _run_tasks(cfg, tasks, workers)
    cells = {}
    out["crosscheck"] = []
    for task, res in zip(tasks, results):
        kind = task[0]
        if kind == "point":
            if isinstance(res, str):
                out["notes"].append(f"operating point '{task[1]}': not linearised ({res})")
            else:
                res["requirement_operating_point"] = task[1]
                out["analyses"].append(res)
        elif kind == "crosscheck":
            out["crosscheck"].extend(res)
        elif kind == "governor":
            out["governor"] = res
        else:
            cells[(task[1], task[2])] = res
    if with_map:
        out["map"] = _assemble_map(positions, loads, cells)
    # the order of the keys as before: analyses, notes, map, crosscheck, governor
    return jsonable({k: out[k] for k in ("schema", "analyses", "notes", "map", "crosscheck", "governor") if k in out})


def _crosscheck_points(stroke: float):
    from compliance.linear.maps import PAPER_POINTS

    return [(f * stroke, ld) for f, ld in PAPER_POINTS]


def _map_grid(cfg: PlantConfig):
    import numpy as np

    from compliance.linear.maps import DEFAULT_LOADS

    positions = [float(x) for x in np.linspace(0.0, cfg.p("cylinder.stroke"), 11)]
    loads = [float(v) for v in DEFAULT_LOADS] + (["curve"] if cfg.load_curve is not None else [])
    return positions, loads


def _task(cfg: PlantConfig, task):
    """One independent piece of the linear analysis (runs in a worker)."""
    from compliance.linear.analysis import analyse
    from compliance.linear.governor_model import governor_parameters
    from compliance.linear.maps import crosscheck, operating_map

    kind = task[0]
    if kind == "point":
        try:
            return analyse(cfg, task[2], task[3], flow_control=task[4]).to_dict()
        except InputError as exc:
            return str(exc)
    if kind == "crosscheck":
        return crosscheck(cfg, points=[(task[1], task[2])])
    if kind == "governor":
        return governor_parameters(cfg).to_dict()
    m = operating_map(cfg, positions=[task[4]], loads=[task[3]], curve=False)  # one cell of the map
    return {"values": {n: v[0][0] for n, v in m.values.items()}, "notes": m.notes}


def _assemble_map(positions, loads, cells) -> dict:
    from compliance.linear.maps import MAP_FIGURES, OperatingMap

    values = {n: [[cells[(i, j)]["values"][n] for j in range(len(positions))] for i in range(len(loads))]
              for n in MAP_FIGURES + ("stable",)}
    notes = [n for i in range(len(loads)) for j in range(len(positions)) for n in cells[(i, j)]["notes"]]
    return OperatingMap(positions, loads, values, notes).to_dict()


def _run_tasks(cfg: PlantConfig, tasks: list, workers: int | None) -> list:
    """Results of ``tasks`` in order, on the one executor (``workers`` processes, default the available cores)."""
    from compliance.processes import map_tasks

    if len(tasks) < 4 or (workers is not None and workers <= 1):  # fork and import cost more than a few linearisations
        workers = 1
    out, stats = map_tasks(_task, cfg, list(tasks), workers=workers, progress=False, label="operating points", retries=0)
    stats.raise_if_failed()
    return out

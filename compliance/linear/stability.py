"""Stability margins of the linearised positioning loop at a requirement set's operating points, against
govcheck's margin criterion (results key ``stability``, docs/results-schema.md).

No governor standard gives a stability criterion for the servo-positioner's own loop; govcheck
judges its phase and gain margins against the lower ends of common control practice (phase
margin 30-60 deg, gain margin 6-12 dB): :data:`MARGIN_CRITERION`, our own choice, stated as such
wherever it is printed. The margins come from the same linearisation as ``govcheck linear``
(``linear.analysis.analyse``); with ``--linear`` the analyses already made are reused.
"""

from __future__ import annotations

from compliance.errors import InputError

__all__ = ["CRITERION_BASIS", "MARGIN_CRITERION", "stability_margins"]

MARGIN_CRITERION = {"phase_margin_deg": 30.0, "gain_margin_db": 6.0}
CRITERION_BASIS = ("govcheck's own criterion from common control practice (phase margin 30-60 deg and gain margin "
                   "6-12 dB are the usual lower ends); no governor standard gives one for the servo-positioner's loop")


def _meets(pm, gm, stable) -> bool | None:
    if stable is False:
        return False
    if stable is None or pm is None or gm is None:
        return None
    return pm >= MARGIN_CRITERION["phase_margin_deg"] and gm >= MARGIN_CRITERION["gain_margin_db"]


def _points(cfg, reqset) -> list[tuple[float, object, list[str]]]:
    """Distinct (position [m], load, operating point names) of the requirement set (the throttles do not change
    the small-signal loop about rest: no flow passes them)."""
    from compliance.simulation.scenario import scenario_load

    stroke = cfg.p("cylinder.stroke")
    out: dict = {}
    for op in reqset.operating_points.values():
        if op.initial_position is None:
            continue
        x = op.initial_position.resolve(stroke)
        if not 0.0 <= x <= stroke:
            continue
        load = scenario_load(cfg, op)
        key = (round(x, 6), load if isinstance(load, str) or load is None else round(float(load), 3))
        out.setdefault(key, (x, load, []))[2].append(op.name)
    return list(out.values())


def _margins(cfg, point):
    """Worker: (phase margin [deg], gain margin [dB], stable) at one point, or the reason it was not linearised."""
    from compliance.linear.analysis import analyse

    x, load, _ = point
    try:
        f = analyse(cfg, x, load, detail=False).figures
    except InputError as exc:
        return str(exc)
    return f.get("phase_margin_deg"), f.get("gain_margin_db"), f.get("stable")


def _from_analyses(analyses: list, points) -> list:
    """The margins of ``govcheck linear`` analyses already made, matched to the points by operating point name."""
    by_name = {a.get("requirement_operating_point"): a.get("figures") or {} for a in analyses}
    out = []
    for _, _, names in points:
        f = next((by_name[n] for n in names if n in by_name), None)
        out.append("not linearised" if f is None else (f.get("phase_margin_deg"), f.get("gain_margin_db"), f.get("stable")))
    return out


def _summary(rows: list[dict]) -> str:
    judged = [r for r in rows if r["meets"] is not None]
    if not judged:
        return "not analysed: no operating point could be linearised"
    below = [r for r in judged if not r["meets"]]
    pm = [r["phase_margin_deg"] for r in judged]
    gm = [r["gain_margin_db"] for r in judged]
    crit = f"{MARGIN_CRITERION['phase_margin_deg']:.0f}\u00b0 / {MARGIN_CRITERION['gain_margin_db']:.0f} dB"
    text = f"phase margin {min(pm):.0f}\u2013{max(pm):.0f}\u00b0, gain margin {min(gm):.1f}\u2013{max(gm):.1f} dB; "
    if not below:
        return text + f"all {len(judged)} operating points meet govcheck's {crit} criterion"
    unstable = sum(1 for r in below if r["stable"] is False)
    return text + (f"{len(below)} of {len(judged)} operating points below govcheck's {crit} criterion"
                   + (f", {unstable} unstable" if unstable else ""))


def stability_margins(cfg, reqset, *, analyses: list | None = None, workers: int | None = None) -> dict:
    """Phase and gain margins at every distinct operating point of ``reqset``, against :data:`MARGIN_CRITERION`.

    Parameters
    ----------
    cfg : PlantConfig
    reqset : RequirementSet
    analyses : list, optional
        ``linear["analyses"]`` of a ``govcheck linear`` run on the same points (reused, nothing re-linearised).
    workers : int, optional
        Processes for the linearisations.

    Returns
    -------
    dict
        ``{"criterion", "points": [{operating_points, position, load, phase_margin_deg, gain_margin_db,
        stable, meets, reason}], "below": [names], "summary"}``; for a plant the linear analysis does
        not cover, ``points`` is empty and ``summary`` says why.
    """
    from compliance.plants import kind_of

    criterion = dict(MARGIN_CRITERION, basis=CRITERION_BASIS)
    why = kind_of(cfg).linear_support(cfg)
    if why is not None:
        return {"criterion": criterion, "points": [], "below": [], "summary": f"not analysed: {why}"}
    points = _points(cfg, reqset)
    if analyses:
        got = _from_analyses(analyses, points)
    else:
        from compliance.processes import map_tasks

        got, _ = map_tasks(_margins, cfg, points, workers=workers if len(points) >= 4 else 1, progress=False,
                           label="stability margins", retries=0)
    rows = []
    for (x, load, names), g in zip(points, got):
        pm, gm, stable = (None, None, None) if isinstance(g, str) else g
        rows.append({"operating_points": names, "position": x, "load": load, "phase_margin_deg": pm,
                     "gain_margin_db": gm, "stable": stable, "meets": _meets(pm, gm, stable),
                     "reason": g if isinstance(g, str) else None})
    return {"criterion": criterion, "points": rows,
            "below": [n for r in rows if r["meets"] is False for n in r["operating_points"]], "summary": _summary(rows)}

"""``reproduce plant-a --calibrate`` end to end: check the output path, fit, print, save, time it."""

from __future__ import annotations

import resource
import time

from compliance.model.config import PlantConfig


FIRST_STAGE_SOBOL = 16  # parameters only: what they can reach, and the base of the effect search
FIRST_STAGE_COMPASS = 6
SECOND_STAGE_SEEDS = 2  # best effect-search points that seed the second stage


def _check_writable(path: str) -> None:
    """Refuse an output path that cannot be written, before any work starts (no folder is created)."""
    from compliance.files.outputs import check_output

    check_output(path, "--calibrate", (".toml",))


def _cpu_seconds() -> float:
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def calibrate_in_stages(cfg: PlantConfig, workers: int | None = None, scheduler: str | None = None):
    """Parameters first; then the effect search; then parameters again with the named valve effect.

    ``scheduler``: every stage's points on one Dask client (``local:N`` or ``tcp://host:port``).

    Returns
    -------
    tuple
        (final Calibration with ``rows_before`` of ``cfg``, parameters-only Calibration,
        effect-search results or [])
    """
    from compliance.effects import EFFECTS
    from compliance.papers.calibration import search_session
    from compliance.papers.calibration_table import NULL_FLOW_EFFECT

    with_effect = NULL_FLOW_EFFECT in EFFECTS and NULL_FLOW_EFFECT not in cfg.effects
    with search_session(scheduler):
        return _stages(cfg, workers, with_effect)


def _stages(cfg: PlantConfig, workers, with_effect: bool):
    from compliance.papers.calibration import calibrate
    from compliance.papers.calibration_effects import effect_search
    from compliance.papers.calibration_table import NULL_FLOW_EFFECT

    first = calibrate(cfg, workers=workers, profiles=not with_effect,
                      **({"sobol_points": FIRST_STAGE_SOBOL, "compass_iterations": FIRST_STAGE_COMPASS} if with_effect else {}))
    if not with_effect:
        return first, first, []
    found = effect_search(first.best, first.conditions, first.rows_after, first.workers)
    null = next(r for r in found if r.name == NULL_FLOW_EFFECT)
    # start from the published plant with the effect at its declared defaults; the parameters-only optimum with
    # the effect at its best starting points seeds the global sample (the landscape has several basins)
    start = cfg.replace(effects={NULL_FLOW_EFFECT: {}})
    seeds = tuple(first.best.replace(effects={NULL_FLOW_EFFECT: p}) for _, p in null.points[:SECOND_STAGE_SEEDS])
    final = calibrate(start, workers=workers, seeds=seeds)
    final.start, final.rows_before, final.cost_before = cfg, first.rows_before, first.cost_before
    final.evaluations += first.evaluations + sum(r.evaluations for r in found)
    return final, first, found


def run_calibration(cfg: PlantConfig, out: str, json_path: str | None = None, scheduler: str | None = None,
                    workers: int | None = None) -> int:
    """Calibrate ``cfg`` to the paper's figures, print the stages, save to ``out`` (``scheduler``: Dask, else
    ``workers`` local processes, default every available core).

    Returns
    -------
    int
        0 (the calibration reports; it does not judge).
    """
    from compliance.model.config import load_plant
    from compliance.papers.calibration_effects import format_effect_search
    from compliance.papers.calibration_reach import format_reach, reach_json, reach_search
    from compliance.papers.calibration_report import calibration_table, save_calibrated
    from compliance.papers.plant_a import compare, format_table

    _check_writable(out)
    if json_path:
        _check_writable(json_path)
    t0, c0 = time.perf_counter(), _cpu_seconds()
    final, first, found = calibrate_in_stages(cfg, workers=workers, scheduler=scheduler)
    wall, cpu = time.perf_counter() - t0, _cpu_seconds() - c0
    # serial: one figure's test is a few ms, less than a process pool costs per poll
    reach = reach_search(final.best, final.conditions, final.rows_after, workers=1)
    reach_wall, reach_cpu = time.perf_counter() - t0 - wall, _cpu_seconds() - c0 - cpu
    columns = [("published", final.rows_before), ("parameters", first.rows_after)]
    if found:
        columns.append(("+ null flow", final.rows_after))
    print(calibration_table(final, columns))
    if found:
        print("\n" + format_effect_search(found, first.cost_after))
    print("\n" + format_reach(reach))
    print(f"\ncalibration: {wall:.1f} s wall, {cpu:.1f} s CPU over all processes "
          f"(= {cpu / max(final.workers, 1):.1f} s on {final.workers} idle cores); reach search: {reach_wall:.1f} s wall, "
          f"{reach_cpu:.1f} s CPU")
    saved = save_calibrated(final, out)
    print(f"saved {saved}: every changed value has source = \"calibrated to seed 000 figures ...\"\n")
    best = load_plant(saved)
    print(format_table(compare(best, explain=False)))
    if json_path:
        from compliance.files.atomic import write_json_atomic

        write_json_atomic(json_path, {
            "plant": best.name, "calibrated_file": saved, "conditions": final.conditions,
            "cost_published": final.cost_before, "cost_parameters_only": first.cost_after,
            "cost_final": final.cost_after, "values": final.values, "evaluations": final.evaluations,
            "wall_s": wall, "cpu_s": cpu, "reach_wall_s": reach_wall, "reach_cpu_s": reach_cpu,
            "columns": {label: [r.__dict__ for r in rows] for label, rows in columns},
            "profiles": [p.__dict__ for p in final.profiles],
            "effect_search": [{"name": r.name, "cost": r.cost, "params": r.params, "closes": r.closes,
                               "opens": r.opens} for r in found],
            "reach": reach_json(reach),
        })
    return 0

"""``reproduce plant-a --calibrate`` end to end: check the output path, fit, print, save, time it."""

from __future__ import annotations

import os
import resource
import time
from pathlib import Path

from compliance.errors import InputError
from compliance.model.config import PlantConfig


def _check_writable(path: str) -> None:
    """Refuse an output path that cannot be written before any work starts."""
    folder = Path(path).resolve().parent
    probe = folder
    while not probe.exists():
        probe = probe.parent
    if not probe.is_dir() or not os.access(probe, os.W_OK):
        raise InputError(f"{path}: cannot write the calibrated configuration there (folder {probe} is not writable)")
    if Path(path).is_dir():
        raise InputError(f"{path}: is a folder; give a .toml file name")


def _cpu_seconds() -> float:
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def run_calibration(cfg: PlantConfig, out: str, json_path: str | None = None) -> int:
    """Calibrate ``cfg`` to the paper's figures, print the before/after, save to ``out``.

    Returns
    -------
    int
        0 (the calibration reports; it does not judge).
    """
    from compliance.papers.calibration import calibrate
    from compliance.papers.calibration_report import calibration_table, save_calibrated
    from compliance.papers.plant_a import compare, format_table

    _check_writable(out)
    if json_path:
        _check_writable(json_path)
    t0, c0 = time.perf_counter(), _cpu_seconds()
    cal = calibrate(cfg)
    wall, cpu = time.perf_counter() - t0, _cpu_seconds() - c0
    print(calibration_table(cal))
    print(f"calibration: {wall:.1f} s wall, {cpu:.1f} s CPU over all processes "
          f"(= {cpu / max(cal.workers, 1):.1f} s on {cal.workers} idle cores)")
    saved = save_calibrated(cal, out)
    print(f"saved {saved}: every changed value has source = \"calibrated to seed 000 figures ...\"\n")
    from compliance.model.config import load_plant

    best = load_plant(saved)
    print(format_table(compare(best, explain=False)))
    if json_path:
        from compliance.files.atomic import write_json_atomic

        write_json_atomic(json_path, {
            "plant": best.name, "calibrated_file": saved, "conditions": cal.conditions,
            "cost_before": cal.cost_before, "cost_after": cal.cost_after,
            "values": cal.values, "evaluations": cal.evaluations, "wall_s": wall, "cpu_s": cpu,
            "before": [r.__dict__ for r in cal.rows_before], "after": [r.__dict__ for r in cal.rows_after],
            "profiles": [p.__dict__ for p in cal.profiles],
        })
    return 0

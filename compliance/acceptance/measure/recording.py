"""Measure a prepared recording: the cases of its test, by kind.

``measure_test`` dispatches on the test as run (``site.prepared.PreparedTest``): a step series
gives a case per step, every other test one case. A recording that cannot be judged as run gives
one case of its stated kind whose every figure is missing for that reason, so the requirements
that would have judged it say why they did not.
"""

from __future__ import annotations

from compliance.acceptance.measure.case import Case
from compliance.acceptance.measure.holds import measure_hold
from compliance.acceptance.measure.sine import measure_sine
from compliance.acceptance.measure.staircase import measure_staircase
from compliance.acceptance.measure.steps import measure_steps
from compliance.acceptance.measure.strokes import measure_stroke

__all__ = ["measure_test"]


def measure_test(prep, cfg, *, step_options: dict | None = None, sine: dict | None = None) -> list[Case]:
    """The measured cases of one prepared recording.

    Parameters
    ----------
    prep : PreparedTest
    cfg : PlantConfig
        The plant model (stroke, valve centre and full-opening voltage).
    step_options : dict, optional
        Step-metric options in SI (``final_window`` ...), as a requirement asks them.
    sine : dict, optional
        ``skip_cycles`` and ``cycles`` of the requirement file's sine procedure.
    """
    run, cond, name = prep.test, prep.cond, prep.name
    if prep.problem:
        conditions = {"position": run.position, "load": run.load, "flow_control": run.flow_control,
                      "direction": run.settings.get("direction")}
        return [Case(name, run.procedure_kind or "unknown", f"{name} (not judged)", conditions, {}, (), {}, prep.problem)]
    if run.kind == "step_series":
        return measure_steps(name, cond, run, cfg, step_options)
    if run.kind == "full_stroke":
        return measure_stroke(name, cond, run, cfg)
    if run.kind == "hold":
        return measure_hold(name, cond, run, cfg)
    if run.kind == "dead_band_staircase":
        return measure_staircase(name, cond, run, cfg)
    sine = sine or {}
    return measure_sine(name, cond, run, cfg, sine.get("skip_cycles", 0.5), sine.get("cycles"))

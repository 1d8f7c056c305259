"""Simulate one scenario: the configuration's controller decides which compiled loop runs it."""

from __future__ import annotations

import math

import pandas as pd

from compliance.errors import InputError
from compliance.model.config import PlantConfig
from compliance.simulation.pid_loop import simulate_pid
from compliance.simulation.scenario import Scenario


def simulate(cfg: PlantConfig, scenario: Scenario) -> pd.DataFrame:
    """Simulate one scenario and return a DataFrame with the canonical recording columns.

    Parameters
    ----------
    cfg : PlantConfig
    scenario : Scenario

    Returns
    -------
    pandas.DataFrame
        One row per controller sample; columns ``OUTPUT_COLUMNS`` (SI, absolute pressures).

    Raises
    ------
    InputError
        Scenario outside the plant (initial position outside the stroke, bad duration).
    SimulationError
        The state became non-finite or non-physical.
    """
    stroke = cfg.p("cylinder.stroke")
    if not (0.0 <= scenario.initial_position <= stroke):
        raise InputError(f"initial position {scenario.initial_position*1e3:.1f} mm is outside the stroke 0..{stroke*1e3:.0f} mm")
    if not (scenario.duration > 0 and math.isfinite(scenario.duration)):
        raise InputError(f"duration must be a positive number of seconds, got {scenario.duration}")
    if scenario.command is None and cfg.options["controller.type"] != "pid":
        # imported here: its design step loads python-control (~1 s), which PID runs never need
        from compliance.simulation.state_feedback_loop import simulate_state_feedback

        return simulate_state_feedback(cfg, scenario)
    return simulate_pid(cfg, scenario)

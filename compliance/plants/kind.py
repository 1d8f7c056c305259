"""The interface of a plant kind: the pieces in which a PID servo and a state-feedback drive differ.

The plant itself (``model.assembly.plant_rhs``, its effects, its rest state) is one for every kind;
a kind brings the controller around it and what follows from that controller: the loop that
closes it, the error band it leaves at rest, whether its operating points have govcheck's
closed-loop linear model, whether the diagnosis can replay its recordings, the controller it
runs on the tracking loop and which settings a remedy may change on site. One implementation per kind (``pid_servo``, ``state_feedback_drive``); the rest of the
package asks ``compliance.plants.kind_of(cfg)`` and names no kind.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod

import pandas as pd

from compliance.errors import InputError
from compliance.model.config import PlantConfig
from compliance.simulation.pid_loop import simulate_pid
from compliance.simulation.scenario import Scenario

__all__ = ["PlantKind"]


class PlantKind(ABC):
    """One family of plant behind one interface.

    Attributes
    ----------
    name : str
        The value of the configuration's ``controller.type`` that selects it.
    title : str
        The kind in words (messages, notes).
    remedy_space : dict
        On-site settings a remedy search may change without new hardware: parameter path ->
        (low factor, high factor, absolute floor of the high end [SI]) around the configured value
        (commissioning ranges, our choice).
    setpoint_limiter : bool
        Its loop has the set-point rate limiter (a remedy may switch it on).
    """

    name: str
    title: str
    remedy_space: dict[str, tuple[float, float, float]]
    setpoint_limiter: bool

    # ---- controller loop -------------------------------------------------------------------------
    def simulate(self, cfg: PlantConfig, scenario: Scenario) -> pd.DataFrame:
        """Simulate one scenario: a plant-only run on its valve command, or the kind's closed loop.

        Returns
        -------
        pandas.DataFrame
            One row per controller sample; the canonical recording columns (SI, absolute pressures).

        Raises
        ------
        InputError
            Scenario outside the plant (initial position outside the stroke, bad duration) or
            one the kind's loop cannot start.
        SimulationError
            The state became non-finite or non-physical.
        """
        stroke = cfg.p("cylinder.stroke")
        if not (0.0 <= scenario.initial_position <= stroke):
            raise InputError(f"initial position {scenario.initial_position*1e3:.1f} mm is outside the stroke 0..{stroke*1e3:.0f} mm")
        if not (scenario.duration > 0 and math.isfinite(scenario.duration)):
            raise InputError(f"duration must be a positive number of seconds, got {scenario.duration}")
        if scenario.command is not None:
            return simulate_pid(cfg, scenario)  # plant only: the valve command drives it, no controller runs
        return self.closed_loop(cfg, scenario)

    @abstractmethod
    def closed_loop(self, cfg: PlantConfig, scenario: Scenario) -> pd.DataFrame:
        """The closed loop of the kind's controller following ``scenario.reference``."""

    def warm_up(self, cfg: PlantConfig) -> None:
        """Compile (or load from the numba cache) the kind's loops once, before workers fork."""
        simulate_pid(cfg, Scenario(0.01, 0.5 * cfg.p("cylinder.stroke")))

    @abstractmethod
    def axis_controller(self, cfg: PlantConfig, settings: dict) -> tuple[str, bool, str]:
        """(controller mode of the tracking loop, friction compensation, words) for a tracking procedure.

        ``settings``: the procedure's (``pid``: run the configuration's PID instead;
        ``without_compensation``).
        """

    # ---- rest ------------------------------------------------------------------------------------
    @abstractmethod
    def stall_error(self, cfg: PlantConfig, direction: str = "opening") -> float:
        """Error band the controller leaves at rest, below which it no longer opens the valve [m]."""

    # ---- operating points and linearisation ------------------------------------------------------
    @abstractmethod
    def linear_support(self, cfg: PlantConfig) -> str | None:
        """None when govcheck's closed-loop linear model covers this kind (``compliance.linear``: the
        requirement set's operating points trimmed, linearised and closed with the controller), else why not.

        The linear analysis, its requirement values and its python-control form read it before any work.
        """

    def check_linear(self, cfg: PlantConfig) -> None:
        """Raise ``InputError`` naming the plant when the kind has no closed-loop linear model."""
        why = self.linear_support(cfg)
        if why is not None:
            raise InputError(f"{cfg.path or cfg.name}: {why}")

    # ---- diagnosis -------------------------------------------------------------------------------
    @abstractmethod
    def diagnosis_support(self, cfg: PlantConfig) -> str | None:
        """None when the diagnosis can replay this kind's closed-loop recordings, else the reason it cannot."""

    def check_diagnosable(self, cfg: PlantConfig) -> None:
        """Raise ``InputError`` naming the plant when the diagnosis cannot replay its recordings."""
        why = self.diagnosis_support(cfg)
        if why is not None:
            raise InputError(f"{cfg.path or cfg.name}: {why}")

"""Plant kinds: each family of plant in its own module behind one interface (``kind.PlantKind``).

A configuration's ``controller.type`` selects its kind: plant A's PID servo with dead-zone
compensation (``pid_servo``) or plant B's state-feedback drive with observers
(``state_feedback_drive``). The controller loop, the operating points with a linear model and the
linearisation, the diagnosis's support and the on-site settings a remedy may change are the
kind's; nothing outside this room reads ``controller.type``. ``simulate(cfg, scenario)`` runs a
scenario under the configuration's kind.
"""

from __future__ import annotations

from compliance.errors import InputError, did_you_mean
from compliance.model.config import PlantConfig
from compliance.plants.kind import PlantKind
from compliance.plants.pid_servo import PID_SERVO
from compliance.plants.state_feedback_drive import STATE_FEEDBACK_DRIVE
from compliance.simulation.scenario import Scenario

__all__ = ["KINDS", "PlantKind", "kind_of", "simulate"]

KINDS: dict[str, PlantKind] = {k.name: k for k in (PID_SERVO, STATE_FEEDBACK_DRIVE)}


def kind_of(cfg: PlantConfig) -> PlantKind:
    """The kind of plant ``cfg`` is (its ``controller.type``).

    Raises
    ------
    InputError
        A controller type no kind implements.
    """
    name = cfg.options["controller.type"]
    if name not in KINDS:
        raise InputError(f"{cfg.path or cfg.name}: controller.type '{name}' is not a plant kind{did_you_mean(name, KINDS)} "
                         f"(kinds: {', '.join(KINDS)})")
    return KINDS[name]


def simulate(cfg: PlantConfig, scenario: Scenario):
    """Simulate one scenario under the configuration's kind (``PlantKind.simulate``).

    Returns
    -------
    pandas.DataFrame
        One row per controller sample; columns ``simulation.OUTPUT_COLUMNS`` (SI, absolute pressures).

    Raises
    ------
    InputError
        Scenario outside the plant (initial position outside the stroke, bad duration).
    SimulationError
        The state became non-finite or non-physical.
    """
    return kind_of(cfg).simulate(cfg, scenario)

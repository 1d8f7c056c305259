"""Plant A's kind: a PID servo with dead-zone compensation (seed 000), the governor servo govcheck judges.

Its loop is the compiled PID loop (``simulation.pid_loop``: sensor filter, delay lines, set-point
rate limiter); its operating points are the requirement set's, each linearised by ``compliance.linear``
as the closed loop of the plant's Jacobian and the sampled PID; the diagnosis replays its
recordings with that same loop.
"""

from __future__ import annotations

from compliance.model.config import PlantConfig
from compliance.model.pid_controller import stall_error
from compliance.plants.kind import PlantKind
from compliance.simulation.pid_loop import simulate_pid

__all__ = ["PID_SERVO", "PidServo"]


class PidServo(PlantKind):
    """The PID servo: ``controller.type = "pid"``."""

    name = "pid"
    title = "PID servo with dead-zone compensation"
    # commissioning ranges around the configured values: gains x0.5-x3, throttles x0.6-x1.5, regulator -20 %/+15 %
    remedy_space = {
        "controller.kp": (0.5, 3.0, 0.0),
        "controller.ki": (0.0, 10.0, 50.0),
        "controller.kd": (0.0, 2.0, 10.0),
        "controller.compensation_width": (0.0, 2.0, 0.8),
        "controller.compensation_dead_zone_positive": (0.7, 1.3, 0.0),
        "controller.compensation_dead_zone_negative": (0.7, 1.3, 0.0),
        "flow_control.opening_conductance": (0.6, 1.5, 0.0),
        "flow_control.closing_conductance": (0.6, 1.5, 0.0),
        "air.supply_pressure": (0.8, 1.15, 0.0),
    }
    setpoint_limiter = True

    def closed_loop(self, cfg: PlantConfig, scenario):
        return simulate_pid(cfg, scenario)

    def axis_controller(self, cfg: PlantConfig, settings: dict) -> tuple[str, bool, str]:
        return "pid", False, "PID"

    def stall_error(self, cfg: PlantConfig, direction: str = "opening") -> float:
        return stall_error(cfg, direction)  # the smoothed dead-zone inverse's stall band (reference-plant.md)

    def linear_support(self, cfg: PlantConfig) -> str | None:
        return None  # linear.analysis: the plant's Jacobian closed with the sampled PID and its dead-zone inverse

    def diagnosis_support(self, cfg: PlantConfig) -> str | None:
        return None


PID_SERVO = PidServo()

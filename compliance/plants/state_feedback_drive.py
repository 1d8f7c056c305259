"""Plant B's kind: a state-feedback drive with acceleration and friction observers (seed 001).

Its loop is the compiled tracking loop (``simulation.state_feedback_loop``), which also runs the
configuration's PID for comparison; its controller is designed on a linear model of the axis
(``model.axis_design``, docs/plant-b.md), so govcheck's closed-loop linear analysis of the PID does
not apply, and the diagnosis, whose replay runs the PID loop, does not replay its recordings.
"""

from __future__ import annotations

from compliance.model.config import PlantConfig
from compliance.plants.kind import PlantKind

__all__ = ["STATE_FEEDBACK_DRIVE", "StateFeedbackDrive"]


class StateFeedbackDrive(PlantKind):
    """The state-feedback drive: ``controller.type = "state_feedback"``."""

    name = "state_feedback"
    title = "state feedback on x, v, a with acceleration and friction observers"
    remedy_space = {  # pole and observer bandwidths x0.5-x2 around the design, regulator -20 %/+15 %
        "controller.closed_loop_bandwidth": (0.5, 2.0, 0.0),
        "controller.acceleration_observer_bandwidth": (0.5, 2.0, 0.0),
        "controller.friction_observer_bandwidth": (0.5, 2.0, 0.0),
        "air.supply_pressure": (0.8, 1.15, 0.0),
    }
    setpoint_limiter = False

    def closed_loop(self, cfg: PlantConfig, scenario):
        # imported here: its design step loads python-control (~1 s), which a PID servo's runs never need
        from compliance.simulation.state_feedback_loop import simulate_state_feedback

        return simulate_state_feedback(cfg, scenario)

    def warm_up(self, cfg: PlantConfig) -> None:
        from compliance.simulation.state_feedback_loop import warm_up

        super().warm_up(cfg)
        warm_up(cfg)

    def axis_controller(self, cfg: PlantConfig, settings: dict) -> tuple[str, bool, str]:
        if settings["pid"]:
            return "pid", False, "PID"
        comp = cfg.options["controller.friction_compensation"] == "true" and not settings["without_compensation"]
        return "state_feedback", comp, "state feedback + friction compensation" if comp else "state feedback"

    def stall_error(self, cfg: PlantConfig, direction: str = "opening") -> float:
        return 0.0  # no dead-zone compensation: the integral-free state feedback has no stall band of its own

    def linear_support(self, cfg: PlantConfig) -> str | None:
        return (f"controller.type = '{self.name}': the linear closed-loop analysis and its python-control form cover "
                f"the PID only; a {self.title} is designed on its own linear model of the axis")

    def diagnosis_support(self, cfg: PlantConfig) -> str | None:
        return (f"validate and diagnose replay a closed-loop recording with the PID loop; a {self.title} has no "
                "closed-loop replay (its observers' states are not recorded)")


STATE_FEEDBACK_DRIVE = StateFeedbackDrive()

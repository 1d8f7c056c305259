"""Simulation: the compiled fixed-step loops (PID and state feedback share one RK4 step and one
sample recorder), scenarios and set-point profiles. Which loop runs a configuration's closed loop is
its plant kind's choice (``compliance.plants.simulate``)."""

from compliance.simulation.rk4 import OUTPUT_COLUMNS
from compliance.simulation.scenario import Scenario, SensorNoise

__all__ = ["OUTPUT_COLUMNS", "Scenario", "SensorNoise"]

"""Plant B (seed 001): single-axis tracking drive and the 3-axis servo-pneumatic path-tracking robot.

- ``design``: linear (x, v, a) model from ``plant_rhs`` Jacobians, pole placement, observer gains;
- ``controller`` / ``observers``: state feedback, reduced-order observers (eqs. 10-11), compensation;
- ``simulate_tracking``: the compiled loop of one axis (``simulate_axis``);
- ``paths``: circle, helix, CSV stroke paths, time parameterisation;
- ``robot``: the Cartesian robot of three axes; ``metrics_tracking``: path and stick-slip metrics;
- ``tracking_procedures``: procedure kinds, metrics and runners for the harness (``run_procedure``);
- ``flow_rating`` / ``flow_trend``: flow-law coefficients from a rating, the flow-law experiment.

See docs/plant-b.md.
"""

from .controller import ControllerDesign, controller_vector
from .design import AxisModel, axis_model
from .metrics_tracking import path_deviation, robot_metrics, stick_slip_episodes
from .paths import Trajectory, circle, helix, read_path_csv, stroke_path, time_parameterise
from .robot import Robot, cartesian_robot, run_robot
from .simulate_tracking import AxisReference, simulate_axis
from .tracking_procedures import KINDS, METRICS, RUNNERS, harness_runner, register, run_procedure, warm_up

__all__ = [
    "KINDS",
    "METRICS",
    "RUNNERS",
    "AxisModel",
    "AxisReference",
    "ControllerDesign",
    "Robot",
    "Trajectory",
    "axis_model",
    "cartesian_robot",
    "circle",
    "controller_vector",
    "harness_runner",
    "helix",
    "path_deviation",
    "read_path_csv",
    "register",
    "robot_metrics",
    "run_procedure",
    "run_robot",
    "simulate_axis",
    "stick_slip_episodes",
    "stroke_path",
    "time_parameterise",
    "warm_up",
]

"""The 3-axis Cartesian servo-pneumatic robot of seed 001 (fig. 7): three plant-B axes.

Axis x carries the complete y axis, which carries the complete z axis; z carries the tool
(the pen of the "江" experiment). Each axis is one plant-B cylinder with its own moving mass:

    m_z = m,    m_y = m + (m + m_frame),    m_x = m + 2 (m + m_frame)

with m the carriage mass of the configuration and m_frame the mass of a cylinder barrel, guide
and brackets (assumed 1.5 kg). z is vertical and x = 0 is its lowest point, so gravity is a
constant closing load m_z g on it. The orthogonal linear guides take every cross-axis reaction,
so the three axes are dynamically decoupled: each is simulated on its own with its own
controller, designed for its own mass and load (seed 001: "send data to every axis controller").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from compliance.model.config import PlantConfig
from compliance.errors import InputError
from compliance.model.state_feedback import controller_vector
from compliance.tracking.paths import AXES, Trajectory
from compliance.simulation.state_feedback_loop import AxisReference, simulate_axis

FRAME_MASS = 1.5  # kg, barrel + guide + brackets of one axis (assumed)
GRAVITY = 9.81  # m/s^2


@dataclass(frozen=True)
class AxisSpec:
    """One robot axis: its configuration (with its moving mass), gravity load and workspace centre."""

    name: str
    cfg: PlantConfig
    load: float | None
    centre: float


@dataclass(frozen=True)
class Robot:
    """A Cartesian robot of three plant-B axes (x, y, z)."""

    axes: tuple[AxisSpec, AxisSpec, AxisSpec]

    def axis(self, name: str) -> AxisSpec:
        """The axis called ``name``."""
        return self.axes[AXES.index(name)]

    def as_dict(self) -> dict:
        """Plain-JSON summary."""
        return {a.name: {"moving_mass": a.cfg.p("cylinder.moving_mass"), "gravity_load": a.load or 0.0,
                         "centre": a.centre} for a in self.axes}


def cartesian_robot(cfg: PlantConfig, *, frame_mass: float = FRAME_MASS, centre: float | None = None,
                    vertical: str = "z") -> Robot:
    """Build the 3-axis robot from one plant-B configuration.

    Parameters
    ----------
    cfg : PlantConfig
        One axis (its ``cylinder.moving_mass`` is the carriage mass m).
    frame_mass : float
        Mass of an axis's barrel, guide and brackets carried by the axis below it [kg].
    centre : float, optional
        Workspace centre on every axis [m] (default mid-stroke).
    vertical : {"x", "y", "z", "none"}
        The vertical axis (gravity closes it).
    """
    if frame_mass < 0:
        raise InputError(f"robot: frame mass must be >= 0 kg, got {frame_mass}")
    m = cfg.p("cylinder.moving_mass")
    stroke = cfg.p("cylinder.stroke")
    c = 0.5 * stroke if centre is None else float(centre)
    if not 0.0 <= c <= stroke:
        raise InputError(f"robot: workspace centre {c*1e3:.1f} mm is outside the stroke 0..{stroke*1e3:.0f} mm")
    masses = {"z": m, "y": m + (m + frame_mass), "x": m + 2.0 * (m + frame_mass)}
    if vertical not in (*AXES, "none"):
        raise InputError(f"robot: vertical axis '{vertical}' is not one of x, y, z, none")
    axes = []
    for name in AXES:
        acfg = cfg.replace(params={"cylinder.moving_mass": masses[name]}, name=f"{cfg.name}/{name}",
                           sources={"cylinder.moving_mass": "derived"})
        load = masses[name] * GRAVITY if name == vertical else None
        axes.append(AxisSpec(name, acfg, load, c))
    return Robot(tuple(axes))


@dataclass(frozen=True)
class RobotRun:
    """Result of a robot run: one canonical frame per axis plus the trajectory."""

    trajectory: Trajectory
    frames: dict
    robot: Robot

    @property
    def time(self) -> np.ndarray:
        """[s]."""
        return self.frames["x"]["time"].to_numpy()

    def stacked(self, column: str) -> np.ndarray:
        """(n, 3) array of one column of the three axes, in workspace coordinates for positions."""
        cols = []
        for a in self.robot.axes:
            v = self.frames[a.name][column].to_numpy()
            cols.append(v - a.centre if column in ("position", "reference", "position_true") else v)
        return np.column_stack(cols)


def run_robot(robot: Robot, trajectory: Trajectory, *, mode: str | None = None, compensation: bool | None = None,
              feedforward: bool | None = None, compensation_form: str = "inverse", position_noise: float = 0.0,
              position_quantum: float = 0.0, pressure_noise: float = 0.0, seed: int = 0) -> RobotRun:
    """Track a 3-D trajectory with the robot (each axis its own controller and simulation).

    Parameters
    ----------
    robot : Robot
    trajectory : Trajectory
        In workspace coordinates (origin at the axes' centres) [m].
    mode, compensation, feedforward, compensation_form
        Controller choices (``simulate_tracking.simulate_axis``).
    position_noise, position_quantum, pressure_noise : float
        Sensor noise [m], [m], [Pa]; axis i uses seed ``seed + i``.

    Returns
    -------
    RobotRun
    """
    frames = {}
    for i, a in enumerate(robot.axes):
        ref = AxisReference(a.centre + trajectory.position[:, i], trajectory.velocity[:, i], trajectory.acceleration[:, i])
        stroke = a.cfg.p("cylinder.stroke")
        if ref.position.min() < 0 or ref.position.max() > stroke:
            raise InputError(f"robot axis {a.name}: the path spans {ref.position.min()*1e3:.1f}..{ref.position.max()*1e3:.1f} mm, "
                             f"outside the stroke 0..{stroke*1e3:.0f} mm")
        design = controller_vector(a.cfg, mode=mode, compensation=compensation, feedforward=feedforward,
                                   x0=float(ref.position[0]), load=a.load, compensation_form=compensation_form)
        df = simulate_axis(a.cfg, ref, load=a.load, design=design, position_noise=position_noise,
                           position_quantum=position_quantum, pressure_noise=pressure_noise, seed=seed + i)
        df.attrs["axis"] = a.name
        frames[a.name] = df
    return RobotRun(trajectory, frames, robot)

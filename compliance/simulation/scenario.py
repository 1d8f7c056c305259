"""A simulated test as data: duration, start, set-point or valve-command profile, load, noise."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from compliance.simulation.profiles import Profile


@dataclass(frozen=True)
class SensorNoise:
    """Measurement noise of a recording (seeded, so runs are deterministic).

    Attributes
    ----------
    position_std : float
        Gaussian noise on the position [m] (the controller sees it).
    position_quantum : float
        Quantisation step of the position [m] (0: none).
    pressure_std : float
        Gaussian noise on the pressures [Pa] (outputs only).
    pressure_quantum : float
        Quantisation step of the pressures [Pa] (0: none).
    """

    position_std: float = 0.0
    position_quantum: float = 0.0
    pressure_std: float = 0.0
    pressure_quantum: float = 0.0


@dataclass(frozen=True)
class Scenario:
    """One simulated test.

    Attributes
    ----------
    duration : float
        [s].
    initial_position : float
        [m].
    reference : Profile or None
        Position set-point for a closed-loop run (constant initial position when None and
        no command is given).
    command : Profile or None
        Valve voltage for a plant-only (open-loop) run [V]; overrides the controller.
    load : float, "curve" or None
        Closing load [N] (> 0 closes), the configuration's load curve, or none.
    flow_control : bool or None
        Override the configuration's flow-control valves.
    noise : SensorNoise or None
    seed : int
    initial_pressures : tuple of float or None
        (p_A, p_B) [Pa abs]; None = at rest balancing the load.
    position_noise : numpy.ndarray or None
        A given additive position-noise sequence per controller sample [m] (e.g. the noise
        estimated from a recording, for a closed-loop replay); replaces the seeded noise.
    """

    duration: float
    initial_position: float
    reference: Profile | None = None
    command: Profile | None = None
    load: float | str | None = None
    flow_control: bool | None = None
    noise: SensorNoise | None = None
    seed: int = 0
    initial_pressures: tuple[float, float] | None = None
    position_noise: np.ndarray | None = field(default=None, compare=False, repr=False)


def sample_profile(profile: Profile | None, t: np.ndarray, default: float) -> np.ndarray:
    """``profile`` sampled at times ``t`` [s], or ``default`` everywhere when there is none."""
    if profile is None:
        return np.full(t.shape, float(default))
    return np.ascontiguousarray(profile.at(t), dtype=float)


def scenario_load(cfg, op):
    """Scenario load of an operating point: closing force [N], "curve" or None."""
    if op.load == "nominal":
        return cfg.p("load.nominal_force")
    return op.load


def stroke_start_pressures(cfg, direction: str, start: str = "end_stop"):
    """Initial chamber pressures (p_A, p_B) [Pa] of a full stroke, or None for the rest state.

    ``"end_stop"``: the servo sits at the end it starts from, held there by the side that drove it
    (at ``air.stroke_start_charge`` of the supply above atmosphere; 1 = at supply, as the previous
    stroke left it); the side about to drive is exhausted to atmosphere (A drives opening, B closing).
    ``"rest"``: None (the simulator's rest state balancing the load, mean (p_s + p_atm)/2).
    """
    if start == "rest":
        return None
    ps, patm = cfg.p("air.supply_pressure"), cfg.p("air.atmospheric_pressure")
    exhausted = 1.001 * patm  # just above atmosphere: an exhausted chamber still holds its residual air
    held = max(exhausted, patm + cfg.p("air.stroke_start_charge") * (ps - patm))  # 1: at supply, as the stroke left it
    return (exhausted, held) if direction == "opening" else (held, exhausted)

"""A prepared run of the seal-friction bench: signals in SI, velocity, reversal and sliding masks."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Run:
    """One prepared bench run."""

    name: str
    seal: str
    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    pressure_gauge: np.ndarray
    friction: np.ndarray  # measured F - p_g * A [N] (friction plus bench bias)
    after_reversal: np.ndarray
    sliding: np.ndarray
    floor: float  # force noise [N]
    valid: np.ndarray  # samples whose velocity estimate is not smeared across a reversal

    @property
    def pressure(self) -> float:
        """Mean gauge pressure [Pa]."""
        return float(np.mean(self.pressure_gauge))

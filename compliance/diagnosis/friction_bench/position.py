"""Declared bench effect: seal friction that changes along the stroke (``friction_along_stroke``).

A seal's friction follows its contact force, which follows its squeeze; a bore whose diameter
varies along the stroke (a printed or worn bore, a slight taper or ovality) changes the squeeze
and so the friction at every position. Both Stribeck levels are scaled by one smooth factor of
position, expanded to second order about the centre of the travelled range:

    F_C(x, p) = (F_C0 + k_p p_g) * s(x),   F_S(x, p) = (F_S0 + k_p p_g) * s(x),
    s(x) = 1 + a1 (x - x_r) + a2 (x - x_r)^2.

Source: friction of an elastomer seal proportional to its squeeze (Parker O-Ring Handbook
ORD 5700, 2021, section 5 "Dynamic O-ring sealing", running friction); the second-order
expansion in position and the reference x_r are our choices (x_r is not fitted: it is the
median position of the seal's runs, so a1 is the slope at mid-travel). The plant model's effect
``position_dependent_friction`` is its first-order form about mid-stroke, with its own name, bounds and
slots; the two are separate declarations.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from compliance.effects.param import Param
from compliance.effects.position_dependent_friction import MIN_FACTOR  # s(x) floor, the servo effect's alike


@dataclass(frozen=True)
class BenchEffect:
    """A bench-only friction effect: one declaration read by the law, the fit and the report."""

    name: str
    meaning: str
    params: tuple
    equations: str
    source: str


POSITION_FRICTION = BenchEffect(
    name="friction_along_stroke",
    meaning="the seal's friction level changes along the stroke (squeeze varying with the bore)",
    params=(
        Param("position_gradient", "1/m", "relative change of both friction levels per metre of travel at mid-travel, a1",
              0.0, (-40.0, 40.0)),
        Param("position_curvature", "1/m^2", "relative curvature of the friction levels along the stroke, a2",
              0.0, (-2000.0, 2000.0)),
    ),
    equations="F_C,S(x, p) = (F_C0,S0 + k_p p_g) (1 + a1 (x - x_r) + a2 (x - x_r)^2)",
    source="seal friction follows squeeze (Parker O-Ring Handbook ORD 5700, 2021); second-order expansion: our choice",
)


def reference_position(runs) -> float:
    """x_r [m]: the median position of a seal's runs (fixed, not fitted)."""
    return float(np.median(np.concatenate([r.position for r in runs])))


__all__ = ["POSITION_FRICTION", "BenchEffect", "MIN_FACTOR", "reference_position"]

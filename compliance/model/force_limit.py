"""The largest force a plant's cylinder can produce, and loads beyond it refused as typos.

A load more than twice that force (1e9 N for 11.4 kN, a load in the wrong unit) is not a
test condition: the simulator would only report a non-physical state much later. The command
line, the sidecar of a recording and the operating points of requirement files use this one check.
"""

from __future__ import annotations

import math

from compliance.errors import InputError

__all__ = ["cylinder_force_limit", "check_load_force"]


def cylinder_force_limit(cfg) -> float:
    """Largest force the cylinder can produce: (p_s - p_atm) x the pressurised area [N] (docs/reference-plant.md)."""
    cap = math.pi / 4.0 * cfg.p("cylinder.piston_diameter") ** 2
    rod = cap - math.pi / 4.0 * cfg.p("cylinder.rod_diameter") ** 2
    area = cap + rod if cfg.options.get("cylinder.arrangement") == "tandem" else cap  # tandem: A_cap + A_rod per side
    return (cfg.p("air.supply_pressure") - cfg.p("air.atmospheric_pressure")) * area


def check_load_force(cfg, load, where: str) -> None:
    """Refuse a constant load the cylinder cannot possibly hold (more than twice its force at supply).

    Such a load is not a test condition but a typo (1e9 N for 11.4 kN); the solver would only
    report a non-physical state much later.
    """
    if load is None or isinstance(load, str):
        return
    limit = cylinder_force_limit(cfg)
    if not abs(load) <= 2.0 * limit:
        raise InputError(f"{where}: load {load:.4g} N is more than twice the largest force the cylinder of {cfg.name} "
                         f"can produce ({limit:.4g} N = (p_s - p_atm) x piston area); expected a load in N such as 11400")

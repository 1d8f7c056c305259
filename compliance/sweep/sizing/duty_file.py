"""Duty files (TOML, schema ``govcheck-duty/1``): what a gate servo must do, validated at the edge.

Stroke, supply pressure, the closing force over the stroke, the full-stroke times (optional:
the requirement file's window otherwise), the load at which those times are set, and the
template configuration that supplies what sizing does not decide (seals, valve dead zone,
moving mass, controller sample time). One :class:`InputError` naming the file and field.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from compliance.errors import InputError
from compliance.model.config_fields import load_curve_field
from compliance.sweep.sizing.data_file import read_validated
from compliance.units import parse_quantity

__all__ = ["Duty", "load_duty"]


class _DutyIn(BaseModel):
    model_config = ConfigDict(extra="forbid")
    schema_: str = Field(alias="schema")
    name: str
    template: str = "plant-a"
    stroke: str
    supply_pressure: str
    opening_time: str | None = None
    closing_time: str | None = None
    setup_force: str | None = None
    load: dict


@dataclass(frozen=True)
class Duty:
    """A validated duty (SI)."""

    path: str
    name: str
    template: str
    stroke: float
    supply_pressure: float
    opening_time: float | None
    closing_time: float | None
    setup_force: float | None
    force_position: np.ndarray
    force: np.ndarray

    @property
    def max_force(self) -> float:
        """Largest force magnitude over the stroke [N]."""
        return float(np.max(np.abs(self.force)))


def check_duty_physics(path: Path, supply: float, max_force: float, setup_force: float | None) -> None:
    """A duty some gate servo can meet: supply above atmosphere and within the cylinders' rating, a force the
    largest ISO 15552 pair carries at that supply, a set-up load within the duty's own forces.

    Raises
    ------
    InputError
        Naming the duty file and the field.
    """
    from compliance.sweep.sizing.hardware_catalogue import MAX_SUPPLY_GAUGE, STANDARD_ATMOSPHERE
    from compliance.sweep.sizing.size_servo import ISO_15552, LOAD_RATIO, size_cylinders

    if not supply > STANDARD_ATMOSPHERE:
        raise InputError(f"{path}: supply_pressure: {supply / 1e5:.3g} bar abs is not above atmosphere "
                         f"({STANDARD_ATMOSPHERE / 1e5:.4g} bar abs); no cylinder would move (write e.g. \"8 bar abs\")")
    if supply - STANDARD_ATMOSPHERE > MAX_SUPPLY_GAUGE:
        raise InputError(f"{path}: supply_pressure: {(supply - STANDARD_ATMOSPHERE) / 1e5:.3g} bar gauge is above the "
                         f"{MAX_SUPPLY_GAUGE / 1e5:.0f} bar gauge any ISO 15552 cylinder is rated for")
    if not max_force > 0.0:
        raise InputError(f"{path}: load.curve.force: every force is zero; give the closing force the gate needs over the stroke")
    try:
        size_cylinders(max_force, supply, STANDARD_ATMOSPHERE)
    except ValueError:
        bore, rod = ISO_15552[-1]
        area = 3.141592653589793 / 4.0 * (2.0 * bore * bore - rod * rod)
        most = area * LOAD_RATIO * (supply - STANDARD_ATMOSPHERE)
        raise InputError(f"{path}: load.curve.force: {max_force / 1e3:.4g} kN is more than the largest ISO 15552 pair "
                         f"carries at {supply / 1e5:.3g} bar abs: two {bore * 1e3:.0f} mm / {rod * 1e3:.0f} mm cylinders in "
                         f"tandem give {most / 1e3:.4g} kN at {LOAD_RATIO:.0%} of the supply (docs/sizing.md); check the "
                         "unit (kN, not N x 1000) or raise the supply") from None
    if setup_force is not None and not 0.0 <= setup_force <= max_force:
        raise InputError(f"{path}: setup_force: {setup_force / 1e3:.4g} kN is outside the duty's own forces "
                         f"(0 .. {max_force / 1e3:.4g} kN on the load curve)")


def load_duty(source) -> Duty:
    """Read and validate a duty file (see the module note)."""
    path = Path(source)
    raw = read_validated(path, _DutyIn, "govcheck-duty/1", "duty file")
    stroke = parse_quantity(raw.stroke, "m", f"{path}: stroke")
    if stroke <= 0:
        raise InputError(f"{path}: stroke: must be > 0")
    ps = parse_quantity(raw.supply_pressure, "Pa", f"{path}: supply_pressure", pressure=True)
    times = {}
    for key in ("opening_time", "closing_time"):
        text = getattr(raw, key)
        times[key] = None if text is None else parse_quantity(text, "s", f"{path}: {key}")
        if times[key] is not None and times[key] <= 0:
            raise InputError(f"{path}: {key}: must be > 0 s")
    setup = None if raw.setup_force is None else parse_quantity(raw.setup_force, "N", f"{path}: setup_force")
    if set(raw.load) != {"curve"}:
        raise InputError(f"{path}: load: expected one table [load.curve] (position, force), as in a plant file")
    xs, fs = load_curve_field(raw.load["curve"], str(path), stroke)
    check_duty_physics(path, ps, float(np.max(np.abs(fs))) if len(fs) else 0.0, setup)
    return Duty(str(path), raw.name, raw.template, stroke, ps, times["opening_time"], times["closing_time"], setup, xs, fs)

"""An SI quantity in the unit a reader expects: the one place a display conversion is written.

``fmt_quantity(0.136, "m", "mm", 1)`` -> ``136.0 mm``; ``fmt_quantity(-2300.0, "N", "kN", 1, signed=True)``
-> ``-2.3 kN``; ``fmt_quantity(0.231, "s", "ms", digits=3)`` -> ``231 ms``. A value is given in SI
(m, s, N, Pa abs, K, fractions) and shown in a unit of :data:`DISPLAY_SCALE`, either with a fixed
number of ``decimals`` (tables, axis-like labels) or with significant ``digits``
(:func:`compliance.presentation.numbers.fmt_value`, which floors it at the unit's display resolution).
"""

from __future__ import annotations

import math

from compliance.presentation.numbers import fmt_value

__all__ = ["DISPLAY_SCALE", "fmt_quantity", "to_display"]

# (SI unit, display unit) -> how to get there: multiply by a factor (m -> mm) or divide by one (N -> kN; a division
# by 1e5 is exact where a multiplication by 1e-5 is not); absolute temperatures convert with an offset
DISPLAY_SCALE = {
    ("m", "mm"): (1e3, False), ("s", "ms"): (1e3, False), ("m/s", "mm/s"): (1e3, False), ("", "%"): (100.0, False),
    ("m^3", "L"): (1e3, False), ("N", "kN"): (1e3, True), ("Pa", "bar"): (1e5, True), ("Pa", "kPa"): (1e3, True),
    ("K", "\u00b0C"): (1.0, False),
}
_OFFSET = {("K", "\u00b0C"): -273.15}


def to_display(value, si_unit: str, unit: str):
    """``value`` [``si_unit``] in ``unit`` (the same unit, or a pair of :data:`DISPLAY_SCALE`); arrays too."""
    if si_unit == unit:
        return value
    try:
        factor, divide = DISPLAY_SCALE[(si_unit, unit)]
    except KeyError:
        raise ValueError(f"no display conversion from {si_unit!r} to {unit!r}") from None
    if (si_unit, unit) in _OFFSET:
        return value + _OFFSET[(si_unit, unit)]
    return value / factor if divide else value * factor


def fmt_quantity(value, si_unit: str, unit: str, decimals: int | None = None, *, digits: int = 3, signed: bool = False,
                 suffix: str = "", none: str = "\u2013") -> str:
    """An SI value as text in ``unit``: ``decimals`` fixed decimals, else ``digits`` significant ones.

    Parameters
    ----------
    value : float or None
        In ``si_unit`` (None or not finite: ``none``).
    si_unit, unit : str
        The value's SI unit and the unit shown (``"m"``, ``"mm"``; ``""`` and ``"%"`` for a fraction).
    decimals : int, optional
        Fixed decimals (``136.0 mm``); without it, significant digits with the unit's display resolution.
    signed : bool
        Always write the sign (a closing load ``+2.3 kN``, a step ``-5 %``).
    suffix : str
        Words after the unit (``" abs"`` for an absolute pressure).
    """
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return none
    v = to_display(float(value), si_unit, unit)
    if decimals is None:
        text = fmt_value(v, unit, digits)
        return (("+" if signed and v > 0 else "") + text) + suffix
    number = f"{v:+.{decimals}f}" if signed else f"{v:.{decimals}f}"
    return f"{number} {unit}".rstrip() + suffix

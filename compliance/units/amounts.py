"""Amounts: quantities as a requirement file writes them, possibly relative to the stroke.

``"1.6 mm"`` is an absolute length; ``"1 %stroke"`` and ``"20 %stroke/s"`` are fractions of
the servomotor's stroke, resolved only when the plant is known. Units are converted to SI
here, at the edge (``compliance.units``).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

from compliance.errors import InputError
from compliance.units.quantities import parse_quantity

__all__ = ["Amount", "parse_amount", "parse_load", "parse_position"]

_STROKE_RE = re.compile(r"(%|percent)\s*(of\s+)?(the\s+)?stroke", re.IGNORECASE)
_BARE_PERCENT_RE = re.compile(r"\s*[-+0-9.eE]+\s*%\s*")
# SI unit of a metric -> unit of the factor that multiplies the stroke in a "%stroke" amount
_PER_STROKE_UNIT = {"m": "", "m/s": "1/s"}


@dataclass(frozen=True)
class Amount:
    """A quantity as written, possibly relative to the stroke (``"1 %stroke"``).

    ``value`` is SI, or, when ``per_stroke``, the factor that multiplies the stroke [m]
    (``"1 %stroke"`` -> 0.01, ``"20 %stroke/s"`` -> 0.2 [1/s]).
    """

    value: float
    per_stroke: bool
    text: str

    def resolve(self, stroke: float) -> float:
        """SI value for a servomotor of stroke ``stroke`` [m]."""
        return self.value * stroke if self.per_stroke else self.value


def parse_amount(value: Any, si_unit: str, where: str, *, require_unit: bool = True) -> Amount:
    """Read ``"1.6 mm"``, ``"1 %stroke"``, ``"20 %stroke/s"`` or ``"0.25 s"`` into an Amount.

    Parameters
    ----------
    value : str
        Quantity with a unit (bare numbers are refused when ``require_unit``: a limit must say
        what it means).
    si_unit : str
        SI unit of the quantity (``""`` for a fraction such as ``"5 %"``).
    where : str
        File and key path for the error message.
    """
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise InputError(f"{where}: expected a quantity such as '1.6 mm', got {type(value).__name__}")
    if not isinstance(value, str):
        if require_unit and si_unit != "":
            raise InputError(f"{where}: {value!r} has no unit; write it with one, e.g. '{value} {si_unit}'")
        return Amount(parse_quantity(value, si_unit, where), False, str(value))
    if si_unit == "m" and _BARE_PERCENT_RE.fullmatch(value):  # a position in "%" can only be of the stroke
        value = value.rstrip()[:-1].rstrip() + " %stroke"
    if _STROKE_RE.search(value):
        if si_unit not in _PER_STROKE_UNIT:
            raise InputError(f"{where}: '%stroke' applies to positions and speeds, not to a quantity in '{si_unit or 'no unit'}'")
        text = _STROKE_RE.sub("percent", value)
        return Amount(parse_quantity(text, _PER_STROKE_UNIT[si_unit], where), True, value)
    if si_unit != "" and re.fullmatch(r"\s*[-+0-9.eE]+\s*", value):
        if require_unit:
            raise InputError(f"{where}: {value!r} has no unit; expected one convertible to '{si_unit}'")
        try:  # a bare number is SI (command-line options)
            number = float(value)
        except ValueError:
            raise InputError(f"{where}: cannot read {value!r} as a number") from None
        if not math.isfinite(number):
            raise InputError(f"{where}: {value!r}: expected a finite number")
        return Amount(number, False, value)
    return Amount(parse_quantity(value, si_unit, where), False, value)


def parse_position(value: Any, stroke: float, where: str, *, require_unit: bool = True) -> float:
    """A position or a position change [m]: ``"85 %stroke"`` = ``"85 %"``, ``"136 mm"``, ``"0.136 m"``.

    The one syntax for positions in files and on the command line. ``require_unit=False``
    (command-line options) reads a bare number as metres, the CLI's "a bare number is SI".

    Parameters
    ----------
    stroke : float
        Stroke of the servomotor [m], which ``%`` refers to.
    where : str
        File and key, or option, for the error message.
    """
    return parse_amount(value, "m", where, require_unit=require_unit).resolve(stroke)


def parse_load(value: Any, where: str, *, require_unit: bool = True, named: tuple[str, ...] = ("curve",)) -> float | str | None:
    """A closing load (> 0 closes): ``"none"``/``"0"`` -> None, a name in ``named`` -> it, ``"11.4 kN"`` -> 11400.0 [N].

    The one syntax for loads in files and on the command line: ``"curve"`` is the plant's load
    curve, ``"nominal"`` (requirement files) its nominal force; ``require_unit=False``
    (command-line options) reads a bare number as newtons.
    """
    text = str(value).strip() if value is not None else ""
    if text.lower() in ("none", "0", ""):
        return None
    if text.lower() in named:
        return text.lower()
    return parse_amount(value, "N", where, require_unit=require_unit).value

"""Texts of a measured figure beside the model's (model evidence): both values with their units, and the sentence
a reader sees."""

from __future__ import annotations

from compliance.presentation.numbers import fmt_value, unit_text

__all__ = ["direction", "figure_text", "measured_text", "miss", "value_text"]


def _unit(unit: str) -> str:
    return "% of stroke" if unit == "% stroke" else unit_text(unit)


def value_text(v, unit: str) -> str:
    """A figure with its unit (``0.860 mm``, ``0.565 % of stroke``)."""
    return f"{fmt_value(v, '', 3)} {_unit(unit)}"


def measured_text(f: dict) -> str:
    """The measured figure or range of a compared figure."""
    if f.get("measured_range"):
        lo, hi = f["measured_range"]
        return f"{fmt_value(lo, '', 3)}\u2013{fmt_value(hi, '', 3)} {_unit(f['unit'])}"
    return value_text(f["measured"], f["unit"])


def direction(f: dict) -> str | None:
    """``above`` / ``below``: where the modelled figure lies from the measured one (or range)."""
    m = f.get("modelled")
    if m is None:
        return None
    lo, hi = f["measured_range"] if f.get("measured_range") else (f["measured"], f["measured"])
    return "above" if m > hi else "below" if m < lo else None


def miss(f: dict) -> float:
    """Size of a miss relative to the measured figure (to pick the example a reader sees)."""
    m, ref = f.get("modelled"), (f["measured_range"][1] if f.get("measured_range") else f.get("measured"))
    if m is None or not ref:
        return float("inf")
    return abs(m - ref) / abs(ref)


def figure_text(f: dict, *, test: bool = True) -> str:
    """``steady error 0.860 mm modelled, 0.240 mm measured (fig. 10, positive step)``; without the test if not ``test``."""
    got = "not measured" if f.get("modelled") is None else f"{value_text(f['modelled'], f['unit'])} modelled"
    return f"{f['metric']} {got}, {measured_text(f)} measured" + (f" ({f['test']})" if test else "")

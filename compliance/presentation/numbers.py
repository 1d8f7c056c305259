"""The one number/unit formatter and the one status-word table of govcheck.

Everything a person reads (terminal table, JSON ``display`` strings, JUnit messages, the
HTML/PDF report) formats numbers here, so a value reads the same everywhere:

- significant digits by quantity, with a display resolution below which a value is noise
  (a position of 2e-6 mm is "< 0.001 mm", not a measurement);
- no exponent notation for values with a unit; plain numbers get ``1.2×10⁻⁵`` in the report;
- units typeset as a reader expects: ``% stroke``, ``dB``, ``Hz``, ``m³/(s·Pa)``;
- margins in per cent capped at ±100 % ("far inside" / "far beyond"), beyond which a
  percentage says nothing a reader can use.
"""

from __future__ import annotations

import datetime as _dt
import math

__all__ = ["STATUS_WORD", "status_word", "fmt_num", "fmt_value", "fmt_margin_pct", "unit_text", "fmt_date",
           "fmt_si", "si_prefix", "fmt_dbic", "RESOLUTION"]

# requirement / verdict states -> the word shown to a reader (one table for every output)
STATUS_WORD = {"pass": "PASS", "fail": "FAIL", "not_evaluated": "NOT EVALUATED", "open": "OPEN",
               "disabled": "DISABLED", "incomplete": "INCOMPLETE", "uncertain": "UNCERTAIN"}

# display unit -> smallest value worth printing (below it: "< resolution"); the resolution of
# the measurement chain a report claims, not of the float
RESOLUTION = {"mm": 0.001, "s": 0.001, "mm/s": 0.01, "%": 0.01, "N": 0.001, "kN": 0.0001, "bar": 0.0001, "V": 0.0001}

_DASH = "\u2013"
_SUPERSCRIPT = str.maketrans("-0123456789", "\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076\u2077\u2078\u2079")
_UNIT_TEXT = (("%stroke", "% stroke"), ("Pa^0.5", "\u221aPa"), ("^3", "\u00b3"), ("^2", "\u00b2"), ("*", "\u00b7"),
              ("db", "dB"), ("DB", "dB"), ("hz", "Hz"), ("HZ", "Hz"))


def status_word(status: str | None) -> str:
    """Upper-case word of a verdict state (``not_evaluated`` -> ``NOT EVALUATED``)."""
    return STATUS_WORD.get(status or "", str(status or _DASH).upper().replace("_", " "))


def unit_text(unit: str | None) -> str:
    """A unit as typeset text: ``%stroke`` -> ``% stroke``, ``m^3/(s*Pa)`` -> ``m³/(s·Pa)``."""
    if not unit:
        return ""
    for a, b in _UNIT_TEXT:
        unit = unit.replace(a, b)
    return unit


def fmt_num(v, digits: int = 4, *, unicode: bool = True) -> str:
    """A plain number: ``digits`` significant digits, whole numbers up to 10⁷, else ``m×10ⁿ``."""
    if v is None:
        return _DASH if unicode else "-"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if not isinstance(v, (int, float)):
        return str(v)
    if not math.isfinite(v):
        return _DASH if unicode else "-"
    if v == 0:
        return "0"
    a = abs(v)
    if 1e-3 <= a < 10**digits:
        s = f"{v:.{digits}g}"
    elif 10**digits <= a < 1e7:
        s = f"{v:.0f}"  # 800000 Pa, 12000 N: whole numbers read better than mantissas
    elif unicode:
        m, e = f"{v:.{digits - 1}e}".split("e")
        mant = m.rstrip("0").rstrip(".") if "." in m else m
        s = f"{mant}\u00d710{str(int(e)).translate(_SUPERSCRIPT)}"
    else:
        s = f"{v:.{digits - 1}e}"
    return s.replace("-", "\u2212") if unicode else s


def fmt_value(v, unit: str = "", digits: int = 3, *, unicode: bool = False, none: str | None = None) -> str:
    """A value already in its display unit, with the unit: ``0.8612`` mm -> ``0.861 mm``.

    Parameters
    ----------
    v : float or None
    unit : str
        Display unit (typeset with :func:`unit_text`); its :data:`RESOLUTION` floors the value.
    digits : int
        Significant digits (trailing zeros kept: ``5.00 s`` says the precision).
    unicode : bool
        Typographic minus sign (report) instead of ASCII (terminal, JSON).
    none : str, optional
        Text of a missing value (default an en dash in the report, ``-`` otherwise).
    """
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return none if none is not None else (_DASH if unicode else "-")
    u = unit_text(unit)
    v = float(v)
    res = RESOLUTION.get(unit or "")
    if res is not None and 0 < abs(v) < res:
        text = f"< {res:g}"
    elif v == 0 or (res is None and abs(v) < 1e-12):
        text = "0"
    elif abs(v) >= 10**digits:
        text = f"{v:.0f}"
    elif res is None and abs(v) < 1e-3:
        text = fmt_num(v, digits, unicode=unicode)
    else:
        text = f"{v:#.{digits}g}".rstrip(".")
        if "e" in text:  # only for values far below any resolution given
            text = fmt_num(v, digits, unicode=unicode)
    if unicode:
        text = text.replace("-", "\u2212")
    return f"{text} {u}".strip() if u != "%" else f"{text} %"


def fmt_margin_pct(pct, *, unicode: bool = True) -> str | None:
    """A margin in per cent of the binding limit, capped: beyond ±100 % it says "far inside/beyond"."""
    if pct is None or not math.isfinite(pct):
        return None
    if pct > 100.0:
        return "far inside (> +100 %)" if unicode else "> +100 %"
    if pct < -100.0:
        return "far beyond (< \u2212100 %)" if unicode else "< -100 %"
    s = f"{pct:+.1f} %"
    return s.replace("-", "\u2212") if unicode else s


def fmt_date(iso: str | None) -> str:
    """ISO time stamp -> ``2026-05-10 12:00 UTC``."""
    if not iso:
        return _DASH
    try:
        d = _dt.datetime.fromisoformat(str(iso))
    except ValueError:
        return str(iso)
    if d.tzinfo is not None:
        return d.astimezone(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return d.strftime("%Y-%m-%d %H:%M")


_PREFIXES = ((1e9, "G"), (1e6, "M"), (1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "\u00b5"), (1e-9, "n"), (1e-12, "p"))


def si_prefix(value, unit: str) -> tuple[float, str]:
    """The scale and prefixed unit that put ``value`` [SI ``unit``] between 1 and 1000: ``1.7e-6 N/Pa`` -> µN/Pa.

    The prefix goes on the unit's first symbol; a first symbol with a power (``m^3``), a
    dimensionless unit and per-unit units (``1/Pa``) keep their unit (scale 1).
    """
    head = unit.split("/")[0].split("*")[0] if unit else ""
    if not head or "^" in head or head[0].isdigit() or head in ("%", "K") or value is None or not math.isfinite(value) \
            or value == 0:
        return 1.0, unit
    if head == "kg":  # already prefixed: grams would read oddly for a mass flow
        return 1.0, unit
    if 0.1 <= abs(value) < 1000.0:
        return 1.0, unit  # "0.93 N" reads better than "930 mN"
    for scale, p in _PREFIXES:
        if abs(value) >= scale * (1 - 1e-12):
            return 1.0 / scale, p + unit
    return 1.0 / _PREFIXES[-1][0], _PREFIXES[-1][1] + unit


def fmt_si(value, unit: str, stderr=None, digits: int = 3) -> str:
    """An SI value (and its standard error) with a sensible prefix, units typeset: ``1.66 ± 0.22 µN/Pa``."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return _DASH
    scale, shown = si_prefix(float(value), unit or "")
    text = f"{float(value) * scale:#.{digits}g}".rstrip(".")
    if "e" in text:
        text = fmt_num(float(value) * scale, digits)
    if stderr is not None and math.isfinite(float(stderr)):
        text += f" \u00b1 {fmt_num(float(stderr) * scale, 2)}"
    return f"{text} {unit_text(shown)}".replace("-", "\u2212").strip()


def fmt_dbic(v) -> str:
    """A BIC difference: whole numbers with thin-space thousands ("6 102 968"), small ones to one decimal."""
    if v is None or not math.isfinite(float(v)):
        return _DASH
    return f"{v:.1f}" if abs(v) < 100 else f"{v:,.0f}".replace(",", "\u2009")

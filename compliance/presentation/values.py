"""The one formatter of a metric's value and of a requirement's limit, for every output.

- :func:`metric_text`: an SI value of a metric in its display unit and digits
  (``0.0016`` m of ``max_positioning_error`` -> ``1.60 mm``);
- :func:`row_texts`: value, limit, margin and margin in per cent of one verdict row;
- :func:`resolved_limit`: the limit resolved against the plant (``<= 1.60 mm``);
- :func:`limit_as_written`: a requirement's limit as its file writes it, with the resolved value
  beside a limit relative to the stroke (``<= 1 %stroke (1.60 mm)``).

``unicode=False`` gives the terminal/JSON/Markdown text (ASCII minus sign, ``<=``), ``True``
the report's (typographic minus, ``≤``, units typeset).
"""

from __future__ import annotations

from collections.abc import Mapping

from compliance.metrics.catalogue import METRICS
from compliance.presentation.numbers import fmt_margin_pct, fmt_value, unit_text

__all__ = ["OPEN_LIMIT", "limit_as_written", "metric_text", "resolved_limit", "row_texts"]

OPEN_LIMIT = "open (purchaser's data sheet)"  # the report's words for a limit the file leaves open
ZERO = 1e-9  # [display unit] below: a numerical zero (a body at rest in stiction), not a measurement


def metric_text(value, metric: str, digits: int = 3, *, unicode: bool = True) -> str:
    """An SI value of ``metric`` in its display unit (``0.0016`` m -> ``1.60 mm``); a metric not declared: as is.

    Parameters
    ----------
    value : float or None
        SI value (None: a dash).
    metric : str
        Name in ``metrics.catalogue.METRICS`` (its display scale and unit).
    digits : int
        Significant digits.
    unicode : bool
        Report text (typographic minus) or terminal/JSON text.
    """
    info = METRICS.get(metric)
    if info is None or value is None:
        return fmt_value(value, "" if info is None else info.display_unit, digits, unicode=unicode)
    v = value * info.display_scale
    return fmt_value(0.0 if abs(v) < ZERO else v, info.display_unit, digits, unicode=unicode)


def resolved_limit(comparator: str, limit, metric: str, *, unicode: bool = False) -> str:
    """A limit resolved to SI, in the metric's display unit: ``<= 1.60 mm``, ``within 0.100 s .. 0.250 s``."""
    head = "within " if comparator == "within" else comparator + " "
    return head + " .. ".join(metric_text(v, metric, unicode=unicode) for v in limit)


def row_texts(row: dict, metric: str, *, unicode: bool = True) -> dict:
    """``value``, ``limit`` (None when open), ``margin`` and ``margin_pct`` of a verdict row, formatted from its SI numbers."""
    return {
        "value": metric_text(row.get("value"), metric, unicode=unicode),
        "limit": None if not row.get("limit") else " .. ".join(metric_text(v, metric, unicode=unicode) for v in row["limit"]),
        "margin": metric_text(row.get("margin"), metric, unicode=unicode),
        "margin_pct": fmt_margin_pct(row.get("margin_pct"), unicode=unicode),
    }


def _typeset(text: str) -> str:
    return text.replace("<=", "\u2264").replace(">=", "\u2265")


def limit_as_written(entry, *, unicode: bool = True) -> str:
    """A requirement's limit as written, with the resolved value beside a limit relative to the stroke.

    ``entry`` is a requirement's verdict (a ``RequirementVerdict``, or a site's entry as its JSON
    has it) with ``limit_text`` as written, ``limit_display`` resolved and ``limit`` SI or None when
    open: ``<= 1 %stroke (1.60 mm)``; in the report ``≤ 1 % stroke (1.60 mm)`` and an open limit in words.
    """
    get = entry.get if isinstance(entry, Mapping) else lambda k: getattr(entry, k)
    written, shown = get("limit_text") or "", get("limit_display") or ""
    if unicode:
        if get("limit") is None:
            return OPEN_LIMIT
        written, shown = _typeset(written).replace(" .. ", " \u2013 "), _typeset(shown)
    text = written or shown
    if "stroke" in written and shown and shown != written:
        text = f"{written} ({shown.split(' ', 1)[-1]})"
    return unit_text(text) if unicode else text

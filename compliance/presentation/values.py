"""The one formatter of a metric's value and of a requirement's limit, for every output.

- :func:`metric_text`: an SI value of a metric in its display unit and digits
  (``0.0016`` m of ``max_positioning_error`` -> ``1.60 mm``);
- :func:`row_texts`: value, limit, margin and margin in per cent of one verdict row, with as many
  digits as it takes to show which side of its limit a judged value lies on (32.007 mm/s against
  32.0 mm/s, never "32.0 mm/s" marked FAIL);
- :func:`band_pct_text`: a band of margins in per cent, rounded outwards so it contains the point margin;
- :func:`resolved_limit`: the limit resolved against the plant (``<= 1.60 mm``);
- :func:`limit_as_written`: a requirement's limit as its file writes it, with the resolved value
  beside a limit relative to the stroke (``<= 1 %stroke (1.60 mm)``).

``unicode=False`` gives the terminal/JSON/Markdown text (ASCII minus sign, ``<=``), ``True``
the report's (typographic minus, ``≤``, units typeset).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from compliance.metrics.catalogue import METRICS
from compliance.presentation.numbers import fmt_margin_pct, fmt_value, unit_text
from compliance.requirements.verdict import Status, evaluate

__all__ = ["OPEN_LIMIT", "band_pct_text", "limit_as_written", "metric_text", "resolved_limit", "row_texts",
           "value_digits", "verdict_texts"]

OPEN_LIMIT = "open (purchaser's data sheet)"  # the report's words for a limit the file leaves open
ZERO = 1e-9  # [display unit] below: a numerical zero (a body at rest in stiction), not a measurement
MAX_DIGITS = 9  # significant digits a judged value may need to show its side of the limit (float round-off beyond)


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


def _getter(obj):
    """Field reader of a verdict row, a worst case or a band: a typed record (``compliance.results``) or its JSON dict."""
    if obj is None:
        return lambda k: None
    return obj.get if isinstance(obj, Mapping) else lambda k: getattr(obj, k, None)


def _point_status(row, limit=None, comparator=None):
    """The row's verdict on its point value: an uncertain row (its band straddles the limit) still has one."""
    get = _getter(row)
    status, value = get("status"), get("value")
    limit, comparator = get("limit") or limit, get("comparator") or comparator
    if status == Status.UNCERTAIN and value is not None and limit and comparator:
        return evaluate(value, comparator, tuple(limit)).status
    return status


def value_digits(row, metric: str, digits: int = 3, *, limit=None, comparator=None) -> int:
    """Significant digits that show a judged row's value on its own side of its limit.

    The printed value, read back as a number, is judged as the row is (a failing value prints
    beyond the limit, a passing one inside it), and a failing value never prints as its limit
    prints: 32.007 mm/s against ``<= 32.0 mm/s`` is "32.007 mm/s", not "32.0 mm/s". ``digits``
    when the row has no verdict (no value, no limit, not judged). ``row`` is a ``VerdictRow`` /
    ``WorstCase`` or its dict; ``limit`` and ``comparator`` stand in when the row does not carry them.
    """
    get = _getter(row)
    info = METRICS.get(metric)
    v, status = get("value"), _point_status(row, limit, comparator)
    lim, comparator = get("limit") or limit, get("comparator") or comparator
    if info is None or v is None or not lim or not comparator or status not in (Status.PASS, Status.FAIL) \
            or not math.isfinite(v) or abs(v * info.display_scale) < ZERO:
        return digits
    lim = tuple(lim)
    limit_texts = {metric_text(x, metric, unicode=False) for x in lim}
    for d in range(digits, MAX_DIGITS + 1):
        shown = float(f"{v * info.display_scale:.{d}g}") / info.display_scale  # the number the text reads
        same_side = evaluate(shown, comparator, lim).status == status
        if same_side and not (status == Status.FAIL and metric_text(v, metric, d, unicode=False) in limit_texts):
            return d
    return MAX_DIGITS


def _margin_text(margin, metric: str, status, *, unicode: bool) -> str:
    """A margin; a failing one reads negative even below the display resolution (``-0.0074 mm/s``, not ``< 0.01``)."""
    text = metric_text(margin, metric, unicode=unicode)
    info = METRICS.get(metric)
    if status == Status.FAIL and margin is not None and margin < 0 and info is not None and text.lstrip().startswith("<"):
        v = margin * info.display_scale
        text = f"{v:.{1 - math.floor(math.log10(-v))}f}"  # two significant digits, fixed point
        text = (text.replace("-", "\u2212") if unicode else text) + (f" {unit_text(info.display_unit)}" if info.display_unit else "")
    return text


def _margin_pct_text(pct, status, *, unicode: bool) -> str | None:
    """A margin in per cent; a failing one never rounds to "-0.0 %" (one more decimal until it reads negative)."""
    text = fmt_margin_pct(pct, unicode=unicode)
    if status == Status.FAIL and pct is not None and -0.05 < pct < 0.0:
        n = min(4, max(2, 1 - math.floor(math.log10(-pct))))
        text = f"{pct:+.{n}f} %"
        text = text.replace("-", "\u2212") if unicode else text
    return text


def row_texts(row, metric: str, *, unicode: bool = True, limit=None, comparator=None) -> dict:
    """``value``, ``limit`` (None when open), ``margin`` and ``margin_pct`` of a verdict row, formatted from its SI numbers.

    ``row`` is a ``VerdictRow`` / ``WorstCase`` or its dict (``limit``/``comparator`` stand in when it
    carries none). The value carries the digits :func:`value_digits` asks for (three at least).
    """
    get = _getter(row)
    status = _point_status(row, limit, comparator)
    lim = get("limit") or limit
    return {
        "value": metric_text(get("value"), metric, value_digits(row, metric, limit=limit, comparator=comparator),
                             unicode=unicode),
        "limit": None if not lim else " .. ".join(metric_text(v, metric, unicode=unicode) for v in lim),
        "margin": _margin_text(get("margin"), metric, status, unicode=unicode),
        "margin_pct": _margin_pct_text(get("margin_pct"), status, unicode=unicode),
    }


def verdict_texts(entry, *, unicode: bool = True) -> dict:
    """:func:`row_texts` of a requirement's deciding (worst) case, judged against the requirement's limit
    (``entry``: a ``RequirementVerdict``); the texts of "no value" when it has none."""
    w = entry.worst
    if w is None:
        return {"value": "\u2013" if unicode else "-", "limit": None, "margin": "-", "margin_pct": None}
    row = next((r for r in entry.rows if r.run == w.run and r.which == w.which), None)  # its own limit
    limit = (row.limit if row is not None else None) or entry.limit
    return row_texts(w, entry.metric, unicode=unicode, limit=limit, comparator=entry.comparator)


def band_pct_text(band, margin_pct=None, *, unicode: bool = False) -> str | None:
    """``[-28..-26 %]``: a band's margins in per cent, rounded outwards to whole per cent so the printed
    band contains the printed point margin (``margin_pct``, widened to it if a band missed it).
    ``band``: a ``Band`` record, its dict or None."""
    get = _getter(band)
    lo, hi = get("margin_low_pct"), get("margin_high_pct")
    if lo is None or hi is None:
        return None
    if margin_pct is not None:
        lo, hi = min(lo, margin_pct), max(hi, margin_pct)
    text = f"[{math.floor(lo):+d}..{math.ceil(hi):+d} %]"
    return text.replace("-", "\u2212") if unicode else text


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

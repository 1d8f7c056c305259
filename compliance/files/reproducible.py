"""``--reproducible`` / ``SOURCE_DATE_EPOCH``: the same inputs give byte-identical output files.

A reproducible results tree carries a fixed ``created`` (``SOURCE_DATE_EPOCH``, else the
epoch), no timings (``timing``, ``runs[].wall_time``) and a command line without the output
paths (which differ between two runs that are compared).
"""

from __future__ import annotations

import datetime as _dt
import os

from compliance.errors import InputError

__all__ = ["fixed_created", "is_reproducible", "make_reproducible"]

_TIMING_KEYS = ("timing", "wall_time", "seconds", "timings")


LAST_SECOND = 253402300799  # 9999-12-31T23:59:59Z


def is_reproducible(flag: bool = False) -> bool:
    """True with ``--reproducible`` or when ``SOURCE_DATE_EPOCH`` is set."""
    return bool(flag) or bool(os.environ.get("SOURCE_DATE_EPOCH", "").strip())


def fixed_created() -> str:
    """ISO timestamp of ``SOURCE_DATE_EPOCH`` (seconds since 1970, UTC), or of the epoch itself.

    Raises
    ------
    InputError
        ``SOURCE_DATE_EPOCH`` is set but not a whole number of seconds.
    """
    text = os.environ.get("SOURCE_DATE_EPOCH", "").strip()
    try:
        seconds = int(text) if text else 0
    except ValueError:
        raise InputError(f"SOURCE_DATE_EPOCH={text!r}: expected a whole number of seconds since 1970-01-01 UTC") from None
    if not 0 <= seconds <= LAST_SECOND:
        raise InputError(f"SOURCE_DATE_EPOCH={text!r}: expected seconds from 0 to {LAST_SECOND} "
                         "(1970-01-01 .. 9999-12-31 UTC, the dates an ISO timestamp can write)")
    return _dt.datetime.fromtimestamp(seconds, _dt.timezone.utc).isoformat(timespec="seconds")


def _strip(obj):
    if isinstance(obj, dict):
        return {k: _strip(v) for k, v in obj.items() if k not in _TIMING_KEYS}
    if isinstance(obj, list):
        return [_strip(v) for v in obj]
    return obj


def make_reproducible(results: dict, command_line: str | None = None) -> dict:
    """Copy of ``results`` with a fixed ``created``, no timings and ``command_line`` replaced.

    Parameters
    ----------
    results : dict
        A results tree (check, gate, validate, diagnose...).
    command_line : str, optional
        The command without output paths; ``None`` keeps the recorded one.
    """
    out = _strip(results)
    if "created" in results or "schema" in results:
        out["created"] = fixed_created()
    if command_line is not None and "command_line" in results:
        out["command_line"] = command_line
    out["reproducible"] = True
    return out

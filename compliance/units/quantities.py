"""One pint registry and the edge conversions: strings with units -> SI floats.

Inside govcheck every quantity is an SI float and every pressure is absolute. Units are
parsed only here, at the edges (configuration, requirement and recording files).
Pressures must say whether they are absolute or gauge (``"8 bar abs"``, ``"7 bar gauge"``)
because a silent 1 bar error would move every force in the model by ~2.4 kN.
"""

from __future__ import annotations

import math
import re
from functools import lru_cache

from compliance.errors import InputError

ATMOSPHERE_PA = 101325.0  # standard atmosphere used to convert gauge readings [Pa]

_PRESSURE_QUALIFIER = re.compile(r"\s*(\(?\s*(abs|absolute|a|gauge|g)\s*\)?)\s*$", re.IGNORECASE)


@lru_cache(maxsize=1)
def registry():
    """Return the single shared pint registry (created lazily).

    Parsing pint's definition files takes ~0.3 s, most of a short command's set-up; pint keeps the
    parsed definitions in its disk cache (``cache_folder``, keyed by the files' contents), here in the
    package's ``__pycache__`` beside the compiled core (``_definitions_cache``).
    """
    import pint

    ureg = pint.UnitRegistry(autoconvert_offset_to_baseunit=True, cache_folder=_definitions_cache(pint))
    ureg.define("percent_stroke = [] = %stroke")
    return ureg


def _definitions_cache(pint) -> str | None:
    """pint's disk cache of this pint version, or None (no cache: a read-only install).

    pint writes its cache files in place; a folder is made whole in a private one and renamed into place in
    one step, so processes starting together (a worker pool, parallel tests) never read a half-written file.
    """
    import os
    import shutil
    import sys
    import tempfile
    from pathlib import Path

    here = Path(__file__).resolve().parents[1] / "__pycache__"
    folder = here / f"pint-{pint.__version__}-py{sys.version_info[0]}{sys.version_info[1]}"
    if folder.is_dir():
        return str(folder)
    try:
        here.mkdir(exist_ok=True)
        fresh = tempfile.mkdtemp(prefix=".pint-", dir=here)
        pint.UnitRegistry(cache_folder=fresh)  # parses the definitions and writes the cache
        try:
            os.rename(fresh, folder)
        except OSError:  # another process renamed its own first: use that one
            shutil.rmtree(fresh, ignore_errors=True)
    except OSError:
        return None
    return str(folder) if folder.is_dir() else None


def _split_pressure_qualifier(text: str):
    m = _PRESSURE_QUALIFIER.search(text)
    if not m:
        return text, None
    word = m.group(2).lower()
    kind = "abs" if word in ("abs", "absolute", "a") else "gauge"
    return text[: m.start()], kind


def parse_quantity(
    value,
    si_unit: str,
    where: str,
    *,
    pressure: bool = False,
    atmosphere: float = ATMOSPHERE_PA,
) -> float:
    """Convert ``value`` (a string with a unit, or a bare number meaning SI) to SI.

    Parameters
    ----------
    value : str or float or int
        ``"125 mm"``, ``"8 bar abs"``, ``"98.17e-5 m^3"``, or a number already in ``si_unit``.
    si_unit : str
        The SI unit expected, e.g. ``"m"``, ``"Pa"``, ``"m^3/(s*Pa)"``, ``""`` for dimensionless.
    where : str
        File and key path, used in the error message.
    pressure : bool
        If true, the value is an absolute pressure: strings must carry ``abs`` or ``gauge``.
    atmosphere : float
        Atmospheric pressure [Pa] used to convert a gauge value.

    Returns
    -------
    float
        The value in ``si_unit`` (absolute pressure in Pa when ``pressure``).
    """
    if isinstance(value, bool):
        raise InputError(f"{where}: expected a quantity in {si_unit or 'no unit'}, got a boolean")
    if isinstance(value, (int, float)):
        out = float(value)
        if not math.isfinite(out):
            raise InputError(f"{where}: value {value!r} is not finite")
        return out
    if not isinstance(value, str):
        raise InputError(f"{where}: expected a string such as '125 mm' or a number, got {type(value).__name__}")
    text = value.strip()
    kind = None
    if pressure:
        text, kind = _split_pressure_qualifier(text)
        if kind is None:
            raise InputError(
                f"{where}: pressure {value!r} is ambiguous; write it as absolute or gauge, "
                f"e.g. '8 bar abs' or '7 bar gauge'"
            )
    ureg = registry()
    try:
        q = ureg.Quantity(text)
    except Exception as exc:  # pint raises many types; all mean "not a quantity"
        raise InputError(f"{where}: cannot read {value!r} as a quantity ({exc.__class__.__name__})") from None
    try:
        if si_unit == "":
            if not hasattr(q, "to"):
                out = float(q)
            else:
                out = float(q.to("dimensionless").magnitude)
        else:
            if not hasattr(q, "to"):
                raise InputError(f"{where}: {value!r} has no unit; expected one convertible to {si_unit}")
            out = float(q.to(si_unit).magnitude)
    except InputError:
        raise
    except Exception:
        have = getattr(q, "units", "no unit")
        raise InputError(f"{where}: {value!r} has unit '{have}', expected one convertible to '{si_unit}'") from None
    if not math.isfinite(out):
        raise InputError(f"{where}: value {value!r} is not finite")
    if kind == "gauge":
        out += atmosphere
    return out


def convert_array(values, unit: str, si_unit: str, where: str, *, pressure_kind: str | None = None):
    """Convert a numpy array from ``unit`` to ``si_unit`` (used for recording columns).

    Parameters
    ----------
    values : numpy.ndarray
    unit : str
        Unit of the values, e.g. ``"mm"``, ``"bar"``, ``"ms"``.
    si_unit : str
        Target SI unit.
    where : str
        File and column, used in the error message.
    pressure_kind : {"abs", "gauge", None}
        For pressures: ``"gauge"`` adds one standard atmosphere after conversion.
    """
    import numpy as np

    ureg = registry()
    try:
        factor_q = ureg.Quantity(1.0, unit)
        factor = float(factor_q.to(si_unit).magnitude)
        offset = float(ureg.Quantity(0.0, unit).to(si_unit).magnitude)
    except Exception:
        raise InputError(f"{where}: unit '{unit}' is not known or not convertible to '{si_unit}'") from None
    out = np.asarray(values, dtype=float) * (factor - offset) + offset
    if pressure_kind == "gauge":
        out = out + ATMOSPHERE_PA
    return out

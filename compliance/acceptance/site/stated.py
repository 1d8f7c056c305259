"""The test a recording holds, as its sidecar states it: kind, conditions and the kind's settings in SI.

The sidecar's ``[test]`` table (declared in ``recordings/sidecar_schema.py``) and ``[conditions]``
become a :class:`SiteTest`; a recording whose sidecar does not say its kind gets one from its
trace (``site.recognise``), which the run says.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from compliance.errors import InputError
from compliance.recordings.sidecar_schema import TEST_KINDS

__all__ = ["PROCEDURE_KIND", "SiteTest", "site_test"]

# a recorded test kind -> the requirement file's procedure kind it stands for
PROCEDURE_KIND = {"step_series": "steps", "full_stroke": "full_stroke", "hold": "hold",
                  "dead_band_staircase": "dead_band", "sine": "sine"}
_POSITION_KEY = {"step_series": "operating_position", "hold": "hold_position", "dead_band_staircase": "operating_position",
                 "sine": "centre"}


@dataclass(frozen=True)
class SiteTest:
    """A test as run (SI).

    Attributes
    ----------
    kind : str or None
        ``step_series``, ``full_stroke``, ``hold``, ``dead_band_staircase`` or ``sine``; None until recognised.
    source : str
        ``"sidecar"`` or how it was recognised.
    load : float, str or None
        Closing load [N] (> 0 closes), ``"curve"`` or None (not said).
    flow_control : bool or None
        True: flow-control valves as commissioned ("set"); False: needles fully open; None: not said.
    position : float or None
        Operating position, hold position or sinusoid centre [m].
    settings : dict
        The kind's keys of the ``[test]`` table (SI).
    supply_pressure : float or None
        [Pa abs].
    notes : tuple of str
    """

    kind: str | None
    source: str
    load: float | str | None
    flow_control: bool | None
    position: float | None
    settings: dict = field(default_factory=dict)
    supply_pressure: float | None = None
    notes: tuple = ()

    @property
    def procedure_kind(self) -> str | None:
        """The requirement file's procedure kind this test stands for."""
        return PROCEDURE_KIND.get(self.kind) if self.kind else None

    def recognised(self, kind: str, how: str, settings: dict, position: float | None) -> "SiteTest":
        """The same run with its kind recognised from the trace (``how`` says from what)."""
        merged = {**settings, **self.settings}
        return replace(self, kind=kind, source=how, settings=merged, position=self.position if self.position is not None else position,
                       notes=self.notes + (f"kind recognised from the trace: {how}",))


def _number(value, where: str, key: str) -> float | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InputError(f"{where}: {key} = {value!r}; expected a number in SI units (or a quantity with its unit)")
    return float(value)


def _numbers(value, where: str, key: str) -> list | None:
    if value is None:
        return None
    if not isinstance(value, list) or not value:
        raise InputError(f"{where}: {key} = {value!r}; expected a non-empty list of numbers")
    return [_number(v, where, f"{key}[{i}]") for i, v in enumerate(value)]


def site_test(metadata: dict, where: str) -> SiteTest:
    """The test of a recording from its sidecar (``read_recording`` metadata, SI).

    Raises
    ------
    InputError
        A setting of the wrong type (a word where a number belongs, a window that is not [start, end]).
    """
    table = metadata.get("test") or {}
    cond = metadata.get("conditions") or {}
    load = cond.get("load_force")
    load = load if load == "curve" else _number(load, where, "conditions.load_force")
    kind = table.get("kind")
    flow = table.get("flow_control")
    settings = {}
    for key, value in table.items():
        if key in ("kind", "flow_control", "loop", "history", "description", "pattern", "approach", "start"):
            continue
        if key in ("direction", "command", "from_rest"):
            settings[key] = value
        elif isinstance(value, list):
            settings[key] = _numbers(value, where, f"test.{key}")
        else:
            settings[key] = _number(value, where, f"test.{key}")
    if "window" in settings and (len(settings["window"]) != 2 or settings["window"][1] <= settings["window"][0]):
        raise InputError(f"{where}: test.window = {table['window']!r}; expected [start, end] in s with end > start")
    if settings.get("direction") not in (None, "opening", "closing"):
        raise InputError(f"{where}: test.direction = {settings['direction']!r}; expected 'opening' or 'closing'")
    position = settings.get(_POSITION_KEY.get(kind, ""), None) if kind else None
    if position is None:
        position = _number(cond.get("initial_position"), where, "conditions.initial_position")
    source = "sidecar" if kind in TEST_KINDS else "not said"
    return SiteTest(kind if kind in TEST_KINDS else None, source, load,
                   None if flow is None else flow == "set", position, settings,
                   _number(cond.get("supply_pressure"), where, "conditions.supply_pressure"))

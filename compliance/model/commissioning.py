"""Commissioning settings: the governor adjustments a plant file says are set on site, from measurements.

A governor's opening and closing times are adjustments of the governor, not properties of its
hardware (IEC 61362:2024 specifies them as adjustable quantities; IEEE Std 125-2007, 5.2.6: adjustable
independently), and the position loop's gain is a tuning parameter of the actuator (IEEE Std
1207-2011 treats the servomotor's gain so); that it is set on site from the measured time constant is
govcheck's reading. A design whose file declares these settings is judged as a test engineer judges
the commissioned machine: at each end of each declared range (a valve that opens fully at 3 V instead
of 4 V, a load a quarter higher) the settings are made again by the measurement the commissioning
engineer makes, and only then are the acceptance tests run (``campaign.commissioning``). Which
settings a plant file declares is its own statement; the rules that make them are govcheck's
(docs/requirements.md, "Commissioned settings").

The plant file's table::

    [commissioning]
    settings = ["limiter_rates", "loop_gain"]
    note = "set on site by timing the strokes and measuring the time constant"

A changed design keeps the table: the settings are the design's adjustments, not measurements.
"""

from __future__ import annotations

from dataclasses import dataclass

from compliance.errors import InputError, did_you_mean

__all__ = ["SETTINGS", "Setting", "commissioning_toml", "parse_commissioning"]


@dataclass(frozen=True)
class Setting:
    """One adjustment made at commissioning: its parameters and the measurement that sets them."""

    name: str
    meaning: str
    parameters: tuple[str, ...]
    measured_by: str


SETTINGS = {s.name: s for s in (
    Setting("limiter_rates", "the set-point rate limiter's opening and closing rates, one per direction",
            ("controller.setpoint_opening_rate", "controller.setpoint_closing_rate"),
            "the requirement file's opening and closing times and stroke rate, timed on its full strokes"),
    Setting("loop_gain", "the position loop's gain K_P (K_I, K_D and the dead-zone inverse's width in proportion) "
            "and the closing side's slope",
            ("controller.kp", "controller.ki", "controller.kd", "controller.compensation_width",
             "controller.compensation_slope_negative"),
            "the requirement file's time-constant steps, with the limiting devices not acting"),
)}
# the order commissioning makes them in: the gain first, since the stroke's lag behind the limiter depends on it
ORDER = ("loop_gain", "limiter_rates")


def parse_commissioning(raw, where: str) -> tuple[str, ...]:
    """Validate a ``[commissioning]`` table -> the declared setting names, in commissioning order.

    Raises
    ------
    InputError
        Not a table, an unknown key, or a setting name govcheck does not know (named with the file).
    """
    if raw is None:
        return ()
    if not isinstance(raw, dict):
        raise InputError(f"{where}: [commissioning] must be a table (settings = [\"limiter_rates\", \"loop_gain\"])")
    unknown = set(raw) - {"settings", "note"}
    if unknown:
        raise InputError(f"{where}: commissioning.{sorted(unknown)[0]}: unknown key (expected settings, note)")
    names = raw.get("settings", [])
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        raise InputError(f"{where}: commissioning.settings: expected a list of setting names "
                         f"({', '.join(SETTINGS)})")
    for n in names:
        if n not in SETTINGS:
            raise InputError(f"{where}: commissioning.settings: '{n}' is not a setting govcheck can commission "
                             f"(expected {', '.join(SETTINGS)}){did_you_mean(n, list(SETTINGS))}")
    if "note" in raw and not isinstance(raw["note"], str):
        raise InputError(f"{where}: commissioning.note: expected a string")
    return tuple(n for n in ORDER if n in names)


def commissioning_toml(settings) -> list[str]:
    """The ``[commissioning]`` table of a saved configuration (empty when nothing is commissioned)."""
    if not settings:
        return []
    return ["[commissioning]", "settings = [" + ", ".join(f'"{s}"' for s in settings) + "]",
            'note = "set on site by the measurement each setting names (govcheck: docs/requirements.md, '
            '\'Commissioned settings\')"', ""]

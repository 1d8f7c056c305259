"""A damaged results file is named, not rendered into a crash: text where a number belongs is refused.

The report and the gate compute with the numbers of a results file; a hand-edited file with text
in such a key (``NUMERIC_KEYS``, at any depth) is refused on reading with the key path.
"""

from __future__ import annotations

from compliance.errors import InputError

__all__ = ["NUMERIC_KEYS", "check_numbers"]

# keys whose values the report computes with: a number, null, or a list of them (text lives in "display" tables)
NUMERIC_KEYS = frozenset({
    "value", "margin", "margin_pct", "wall", "wall_time", "time", "position", "reference", "valve_command",
    "pressure_a", "pressure_b", "supply_pressure", "force", "phase_margin_deg", "gain_margin_db", "time_constant",
    "dead_time", "overshoot", "settling_time", "rise_time", "bandwidth_hz", "natural_frequency_hz", "damping_ratio",
    "gain_crossover_hz", "phase_crossover_hz", "max_error", "rms_error", "steady_error", "peak_speed",
})
_TEXT_TABLES = frozenset({"display", "procedure", "operating_point", "settings", "procedures", "operating_points"})


def check_numbers(data: dict, where: str) -> None:
    """Refuse text where the report computes with a number (``NUMERIC_KEYS``), naming the key path.

    Raises
    ------
    InputError
        The results file is damaged or hand-edited.
    """
    for key in ("requirements", "runs", "timing", "linear", "plant", "site"):
        _check_numbers(data.get(key), f"{where}: {key}")


def _check_numbers(tree, where: str) -> None:
    if isinstance(tree, dict):
        for k, v in tree.items():
            if k in _TEXT_TABLES:
                continue
            if k in NUMERIC_KEYS and not _numbers(v):
                raise InputError(f"{where}.{k}: {str(v)[:60]!r} where a number (or null) belongs; the results file is "
                                 "damaged or hand-edited: regenerate it with govcheck check --json")
            _check_numbers(v, f"{where}.{k}")
    elif isinstance(tree, (list, tuple)) and not _NUMBERS.issuperset(map(type, tree)):
        for i, v in enumerate(tree):
            _check_numbers(v, f"{where}[{i}]")


_NUMBERS = frozenset({float, int, type(None)})  # a signal of a trace: checked at C speed


def _numbers(v) -> bool:
    if isinstance(v, (list, tuple)):
        return _NUMBERS.issuperset(map(type, v)) or all(_numbers(x) for x in v)
    if isinstance(v, dict):
        return True  # a table of its own: its leaves are checked by name
    return v is None or (isinstance(v, (int, float)) and not isinstance(v, bool))

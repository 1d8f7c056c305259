"""The ``[test]`` table of a recording's sidecar: the test as it was run, in physical terms.

A commissioning engineer logs each standard test as its own recording (IEC 60308:2024 /
ASME PTC 29-2005 (R2020) practice) and says in the sidecar what was done: the kind of test, its
step sizes and times, the direction of a stroke, whether the flow-control valves were open or as
commissioned, the hold window, the amplitude and frequency of a sinusoid. Every key is declared
here with its SI unit and the kinds it belongs to; an unknown key gets the closest known one, a
key of another kind says which kind it belongs to, and a quantity of the wrong dimension is named
before any conversion hides it (docs/recording-format.md, "The test as run").

``kind`` may be left out: the acceptance then recognises the test from its trace and says so.
"""

from __future__ import annotations

from compliance.errors import InputError, did_you_mean
from compliance.recordings.sidecar_schema import TEXT, Value, check_sidecar

__all__ = ["COMMON_KEYS", "TEST_KINDS", "FLOW_CONTROL", "check_test_table"]

FLOW_CONTROL = ("open", "set")  # needles of 2V2/2V3 fully open, or as commissioned for the stroke times

COMMON_KEYS: dict = {
    "kind": Value(None, "the kind of test: " + ", ".join(("step_series", "full_stroke", "hold", "dead_band_staircase", "sine"))),
    "flow_control": Value(None, "flow-control valves 'open' (needles fully open) or 'set' (as commissioned)"),
    "duration": Value("s", "length of the recording"),
    "loop": TEXT,
    "history": TEXT,
    "description": TEXT,
}

TEST_KINDS: dict = {
    "step_series": {
        "operating_position": Value("m", "the position the steps start from and return to"),
        "step_sizes_percent_stroke": Value("", "step sizes in per cent of the stroke, e.g. [1, 2]"),
        "pattern": TEXT,
        "step_times": Value("s", "times of the set-point steps (recording time)"),
        "setpoints_after": Value("m", "set-point after each step"),
        "step_changes": Value("m", "signed set-point change of each step"),
        "plateau": Value("s", "time between steps"),
        "from_rest": Value(None, "true when the series starts at rest at the operating position"),
    },
    "full_stroke": {
        "direction": Value(None, "'opening' or 'closing'"),
        "command": Value(None, "'full': the valve command jumps from one limit to the other"),
        "command_before": Value("V", "valve command before the stroke"),
        "command_after": Value("V", "valve command from command_time on"),
        "command_time": Value("s", "time of the command change"),
        "start": TEXT,
        "end_position": Value("m", "the end of travel the stroke runs to"),
    },
    "hold": {
        "hold_position": Value("m", "the position held"),
        "valve_null_from": Value("s", "from this time the positioner is in manual with the valve at null"),
        "valve_command_during_hold": Value("V", "valve command during the hold"),
        "window": Value("s", "[start, end] of the hold window"),
    },
    "dead_band_staircase": {
        "operating_position": Value("m", "the position the staircase is run about"),
        "approach": TEXT,
        "approach_time": Value("s", "time of the approach step"),
        "approach_setpoint": Value("m", "set-point after the approach step"),
        "stair": Value("m", "height of one stair"),
        "stair_period": Value("s", "time between stairs"),
        "up_from": Value("s", "time of the first stair up"),
        "up_stairs": Value("", "number of stairs up"),
        "down_from": Value("s", "time of the first stair down"),
        "down_stairs": Value("", "number of stairs down"),
    },
    "sine": {
        "centre": Value("m", "centre of the sinusoid"),
        "amplitude": Value("m", "amplitude of the sinusoid"),
        "frequency": Value("Hz", "frequency of the sinusoid"),
        "start_time": Value("s", "time the sinusoid starts"),
        "cycles": Value("", "number of periods run"),
    },
}


def _owner(key: str) -> str | None:
    return next((kind for kind, keys in TEST_KINDS.items() if key in keys), None)


def check_test_table(table, where: str) -> None:
    """Every key of a sidecar's ``[test]`` table is declared for its kind, every quantity has the declared kind.

    Parameters
    ----------
    table : dict
        The ``[test]`` table as TOML read it.
    where : str
        The sidecar file, for messages.

    Raises
    ------
    InputError
        Not a table; an unknown kind (with the closest one); a key unknown to every kind (with the
        closest one) or declared for another kind (naming it); ``flow_control`` not open/set; a
        quantity of the wrong dimension.
    """
    if not isinstance(table, dict):
        raise InputError(f"{where}: test: expected a table [test]")
    kind = table.get("kind")
    if kind is not None and kind not in TEST_KINDS:
        raise InputError(f"{where}: test.kind = {kind!r}: unknown kind{did_you_mean(kind, TEST_KINDS)} "
                         f"(known: {', '.join(TEST_KINDS)})")
    every = {**COMMON_KEYS, **{k: v for keys in TEST_KINDS.values() for k, v in keys.items()}}
    allowed = {**COMMON_KEYS, **TEST_KINDS[kind]} if kind else every
    for key in table:
        if key in allowed:
            continue
        owner = _owner(key)
        if owner is not None:
            raise InputError(f"{where}: test.{key}: belongs to a '{owner}' test, not to this '{kind}' test "
                             f"(keys of '{kind}': {', '.join(TEST_KINDS[kind])})")
        raise InputError(f"{where}: test.{key}: unknown key{did_you_mean(key, allowed)} (known: {', '.join(allowed)})")
    flow = table.get("flow_control")
    if flow is not None and flow not in FLOW_CONTROL:
        raise InputError(f"{where}: test.flow_control = {flow!r}: expected 'open' or 'set'{did_you_mean(flow, FLOW_CONTROL)}")
    check_sidecar(table, where, allowed, "test")

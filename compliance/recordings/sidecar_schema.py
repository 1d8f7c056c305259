"""The one declaration of what a recording's sidecar (and a column map's ``[metadata]``) may hold.

Every key the readers, the replay and the characterisation look up is declared here with its
SI unit; anything else is an error with the closest known key (``load_forse`` -> ``load_force``),
so a misspelt key is never silently ignored and its default silently used. A quantity string
of the wrong kind (a load in tonnes, a mass, where a force is expected) is named before any
conversion hides it. The instruments' tables, ``[logger]`` and ``[channels.NAME]``
(docs/recording-format.md), have their own declaration in ``recordings/instruments.py``, which
checks them, and so has the test as run, ``[test]`` (``TEST_KINDS``, :func:`check_test_table`, below).
"""

from __future__ import annotations

from dataclasses import dataclass

from compliance.errors import InputError, did_you_mean

__all__ = ["COMMON_KEYS", "FLOW_CONTROL", "SIDECAR_SCHEMA", "TEST_KINDS", "Free", "Value", "check_sidecar",
           "check_test_table"]


@dataclass(frozen=True)
class Value:
    """One value: its SI unit ("" dimensionless, None text), what it means; ``also`` a word it may be instead."""

    unit: str | None
    meaning: str
    also: tuple[str, ...] = ()


@dataclass(frozen=True)
class Free:
    """A table whose keys are not checked (provenance written by a generator)."""

    meaning: str


TEXT = Value(None, "free text")
SIDECAR_SCHEMA: dict = {
    "plant": Value(None, "the plant: a reference name or a configuration file relative to the sidecar"),
    "description": TEXT, "name": TEXT, "notes": TEXT, "source": TEXT, "licence": TEXT, "license": TEXT,
    "sample_time": Value("s", "logger sample interval"),
    "sample_rate": Value("Hz", "logger sample rate"),
    "bore": Value("m", "piston diameter (friction bench)"),
    "piston_area": Value("m^2", "piston area (friction bench)"),
    "arrangement": Value(None, "cylinder arrangement (single | tandem)"),
    "conditions": {
        "load_force": Value("N", "constant closing load (> 0 closes)", also=("curve",)),
        "initial_position": Value("m", "position at the start of the test"),
        "supply_pressure": Value("Pa", "supply pressure, absolute"),
        "supply_temperature": Value("K", "supply air temperature"),
        "temperature": Value("K", "ambient temperature"),
    },
    "controller": {
        "kp": Value("V/m", "proportional gain"),
        "ki": Value("V/(m*s)", "integral gain"),
        "kd": Value("V*s/m", "derivative gain"),
        "sample_time": Value("s", "controller sample interval"),
    },
    # the instruments' tables are declared and checked in one place, recordings/instruments.py
    "logger": Free("the logger: rate, anti-alias filter (recordings/instruments.py)"),
    "channels": Free("each channel's sensor: delay, resolution, gain, offset (recordings/instruments.py)"),
    "synthesis": Free("how a synthetic recording was made (compliance.recordings.synth)"),
    # the test as run (kind, steps, direction, hold window, ...) is declared and checked below (TEST_KINDS)
    "test": Free("the test as run: kind, step sizes and times, direction, hold window (check_test_table below)"),
}


def check_sidecar(data, where: str, schema: dict | None = None, keys: str = "") -> None:
    """Every key of a sidecar mapping is declared, every quantity string has the declared kind.

    Parameters
    ----------
    data : dict
        The sidecar as TOML read it (before quantity strings become SI floats).
    where : str
        The file (and key path), for messages.
    schema : dict, optional
        The layout to check against (default :data:`SIDECAR_SCHEMA`).
    keys : str
        The key path of ``data`` inside the file ("" at the top).

    Raises
    ------
    InputError
        An unknown key (with the closest known one and the known keys), a table where a value
        belongs or the reverse, a quantity of the wrong dimension (a mass given as a load).
    """
    schema = SIDECAR_SCHEMA if schema is None else schema
    if not isinstance(data, dict):
        raise InputError(f"{where}: {keys or 'top level'}: expected a table")
    for key, value in data.items():
        spec = schema.get(key)
        dotted = f"{keys}.{key}" if keys else str(key)
        path = f"{where}: {dotted}"
        if spec is None:
            raise InputError(f"{path}: unknown key '{key}'{did_you_mean(key, schema)} (known: {', '.join(schema)})")
        if isinstance(spec, Free):
            continue
        if isinstance(spec, dict):
            check_sidecar(value, where, spec, dotted)
        else:
            _check_value(value, spec, path)


def _check_value(value, spec: Value, path: str) -> None:
    if isinstance(value, dict):
        raise InputError(f"{path}: expected a value ({spec.meaning}), not a table")
    if spec.unit is None or not isinstance(value, str) or value.strip() in spec.also:
        return
    from compliance.units import registry

    ureg = registry()
    try:
        q = ureg.Quantity(value.replace(" abs", "").replace(" gauge", ""))
        target = ureg.Quantity(1, spec.unit or "dimensionless")
    except Exception:  # pint raises many types; not a quantity: left to the conversion's own message
        return
    if q.dimensionality != target.dimensionality:
        hint = ""
        if spec.unit == "N" and q.dimensionality == ureg.kg.dimensionality:
            hint = f" - {value} is a mass; as a weight it is {q.to('kg').magnitude * 9.80665:.6g} N (x g = 9.80665 m/s^2)"
        raise InputError(f"{path} = {value!r}: expected {spec.meaning} in {spec.unit or 'no unit'}, got a quantity of "
                         f"another kind{hint}")


# --------------------------------------------------------------------------- the test as run: [test]
# A commissioning engineer logs each standard test as its own recording (IEC 60308:2024 /
# ASME PTC 29-2005 (R2020) practice) and says in the sidecar what was done: the kind of test, its
# step sizes and times, the direction of a stroke, whether the flow-control valves were open or as
# commissioned, the hold window, the amplitude and frequency of a sinusoid. Every key is declared
# here with its SI unit and the kinds it belongs to; an unknown key gets the closest known one, a
# key of another kind says which kind it belongs to (docs/recording-format.md, "The test as run").
# ``kind`` may be left out: the acceptance then recognises the test from its trace and says so.
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

"""The one declaration of what a recording's sidecar (and a column map's ``[metadata]``) may hold.

Every key the readers, the replay and the characterisation look up is declared here with its
SI unit; anything else is an error with the closest known key (``load_forse`` -> ``load_force``),
so a misspelt key is never silently ignored and its default silently used. A quantity string
of the wrong kind (a load in tonnes, a mass, where a force is expected) is named before any
conversion hides it. The instruments' tables, ``[logger]`` and ``[channels.NAME]``
(docs/recording-format.md), have their own declaration in ``recordings/instruments.py``, which
checks them; here they are known keys.
"""

from __future__ import annotations

from dataclasses import dataclass

from compliance.errors import InputError, did_you_mean

__all__ = ["SIDECAR_SCHEMA", "Free", "Value", "check_sidecar"]


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
    "test": Free("the test as run: kind, times, flow-control valves, hold window (the replay reads flow_control and valve_null_from)"),
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

"""Plant configuration files: load, validate at the edge, freeze; save fitted variants with provenance.

The fields themselves are read and checked in :mod:`compliance.model.config_fields`.
"""

from __future__ import annotations

import math
import os
import tomllib
from dataclasses import dataclass, field, replace as dc_replace
from pathlib import Path
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

from compliance.effects import EFFECTS
from compliance.errors import InputError, did_you_mean
from compliance.files.atomic import write_text_atomic
from compliance.files.shipped import resolve_shipped
from compliance.model.assumptions import parse_model_evidence, read_assumptions
from compliance.model.assumptions import commissioning_toml, parse_commissioning
from compliance.model.config_fields import SECTIONS, atmosphere_of, effect_values, load_curve_field, section_values
from compliance.model.parameters import BASE_BY_KEY, BASE_PARAMS, OPTIONS, used_by_model
from compliance.model.identity import parse_identity
from compliance.model.toml_file import read_toml

_TOP_KEYS = {"name", "description", "provenance", "effects", "identity", "model_evidence", "commissioning"}




@dataclass(frozen=True)
class PlantConfig:
    """A validated, frozen plant configuration (all values SI, pressures absolute).

    Attributes
    ----------
    name, description : str
    path : str or None
        File it was read from.
    digest : str
        sha256 of the file bytes ("" for an in-memory configuration).
    params : Mapping[str, float]
        Dotted key -> SI value, every key of ``parameters.BASE_PARAMS``.
    sources : Mapping[str, str]
        Dotted key -> ``paper|assumed|derived|user``.
    options : Mapping[str, str]
        Dotted key -> option string.
    load_curve : tuple of numpy arrays or None
        (position [m], closing force [N]) over the stroke.
    effects : Mapping[str, Mapping[str, float]]
        Effects switched on and their SI parameters.
    provenance : Mapping[str, str]
        Where a fitted configuration came from (parent digest, recording, date).
    """

    name: str
    description: str
    path: str | None
    digest: str
    params: Mapping[str, float]
    sources: Mapping[str, str]
    options: Mapping[str, str]
    load_curve: tuple[np.ndarray, np.ndarray] | None
    effects: Mapping[str, Mapping[str, float]]
    provenance: Mapping[str, str] = field(default_factory=dict)
    identity: Mapping[str, Any] = field(default_factory=dict)  # optional [identity]: site, unit, equipment (model/identity.py)
    assumptions: Mapping[str, Any] = field(default_factory=dict)  # key -> range / derived_for (model/assumptions.py)
    # optional [model_evidence]: the paper and recordings the model answers to (model/assumptions.py)
    model_evidence: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({"paper": None, "recordings": ()}))
    # optional [commissioning]: the governor settings made on site from measurements (model/assumptions.py)
    commissioning: tuple[str, ...] = ()

    def p(self, key: str) -> float:
        """SI value of a base parameter."""
        return self.params[key]

    def load_curve_forces(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The load curve the model applies: (position [m], closing force [N]), the drawn forces x ``load.curve_scale``."""
        if self.load_curve is None:
            return None
        return self.load_curve[0], self.load_curve[1] * self.params.get("load.curve_scale", 1.0)

    def option(self, key: str) -> str:
        """Value of an option such as ``friction.model``."""
        return self.options[key]

    @property
    def flow_control_installed(self) -> bool:
        """Whether the meter-out flow-control valves 2V2/2V3 are in the circuit."""
        return self.options["flow_control.installed"] == "true"

    @property
    def setpoint_rate_limited(self) -> bool:
        """Whether the PID's set-point rate limiter acts (an opening or closing rate is set)."""
        return max(self.params.get("controller.setpoint_opening_rate", 0.0),
                   self.params.get("controller.setpoint_closing_rate", 0.0)) > 0.0

    @property
    def piston_area(self) -> float:
        """Cap-side area A_cap [m^2]."""
        d = self.params["cylinder.piston_diameter"]
        return math.pi * d * d / 4.0

    @property
    def rod_side_area(self) -> float:
        """Rod-side annulus area A_rod [m^2]."""
        d = self.params["cylinder.rod_diameter"]
        return self.piston_area - math.pi * d * d / 4.0

    def with_commissioning(self, settings) -> "PlantConfig":
        """This configuration with the ``[commissioning]`` settings ``settings`` (names of ``model.assumptions.SETTINGS``)."""
        return dc_replace(self, commissioning=parse_commissioning({"settings": list(settings)}, self.path or self.name))

    def replace(self, *, params=None, effects=None, options=None, name=None, provenance=None, sources=None):
        """Return a new configuration with some values changed (validated the same way).

        Parameters
        ----------
        params : dict, optional
            Dotted key -> SI float to override.
        effects : dict, optional
            Effect name -> dict of SI params (merged with defaults), or None to switch it off.
        options : dict, optional
            Option key -> value.
        """
        new_params = dict(self.params)
        new_sources = dict(self.sources)
        for k, v in (params or {}).items():
            if k not in BASE_BY_KEY:
                raise InputError(f"parameter '{k}' is not known{did_you_mean(k, BASE_BY_KEY)}")
            new_params[k] = float(v)
            new_sources[k] = (sources or {}).get(k, "user")
        new_effects = {k: dict(v) for k, v in self.effects.items()}
        for k, v in (effects or {}).items():
            if k not in EFFECTS:
                raise InputError(f"effect '{k}' is not known{did_you_mean(k, EFFECTS)}")
            if v is None:
                new_effects.pop(k, None)
            else:
                merged = EFFECTS[k].defaults()
                merged.update(new_effects.get(k, {}))
                merged.update({pk: float(pv) for pk, pv in v.items()})
                new_effects[k] = merged
        new_options = dict(self.options)
        for k, v in (options or {}).items():
            if k not in OPTIONS:
                raise InputError(f"option '{k}' is not known{did_you_mean(k, OPTIONS)}")
            v = str(v).lower() if isinstance(v, bool) else str(v)
            if v not in OPTIONS[k]:
                raise InputError(f"option {k} = '{v}' is not one of {', '.join(OPTIONS[k])}{did_you_mean(v, OPTIONS[k])}")
            new_options[k] = v
        cfg = dc_replace(
            self,
            name=name or self.name,
            params=MappingProxyType(new_params),
            sources=MappingProxyType(new_sources),
            effects=MappingProxyType({k: MappingProxyType(v) for k, v in new_effects.items()}),
            options=MappingProxyType(new_options),
            provenance=MappingProxyType(dict(provenance)) if provenance is not None else self.provenance,
            # a range or a derivation target was stated about the value the file gave: a new value drops it
            assumptions=MappingProxyType({k: a for k, a in self.assumptions.items() if new_params[k] == self.params[k]}),
        )
        if new_params != dict(self.params) or new_effects != {k: dict(v) for k, v in self.effects.items()} \
                or new_options != dict(self.options):
            # the measurements were taken on the configuration the file gave: a changed design (a remedy, a sized
            # proposal) has none of its own, and the base plant's figures would be compared with another servo
            cfg = dc_replace(cfg, model_evidence=MappingProxyType({"paper": None, "recordings": ()}))
        _check_physical(cfg, self.path or "<configuration>")
        return cfg


# ----------------------------------------------------------------------------------------------
def load_plant(source: str | os.PathLike) -> PlantConfig:
    """Load and validate a plant configuration (a TOML path or a reference plant name).

    Raises
    ------
    InputError
        With the file and key path of the first problem found.
    """
    path = resolve_shipped(source, "plant")
    data, digest = read_toml(path, "plant configuration")
    return plant_from_dict(data, str(path), digest)


def plant_from_dict(data: dict[str, Any], where: str = "<configuration>", digest: str = "") -> PlantConfig:
    """Validate a parsed configuration mapping and freeze it (see ``load_plant``)."""
    if not isinstance(data, dict):
        raise InputError(f"{where}: expected a TOML table at the top level")
    for k in data:
        if k not in _TOP_KEYS and k not in SECTIONS:
            raise InputError(f"{where}: unknown key '{k}'{did_you_mean(k, list(_TOP_KEYS) + SECTIONS)}")
    name = data.get("name")
    if not isinstance(name, str) or not name.strip():
        raise InputError(f"{where}: missing 'name' (a string naming the plant)")
    description = data.get("description", "")
    params, sources, options, load_curve_raw = section_values(data, where)
    load_curve = None
    if load_curve_raw is not None:
        load_curve = load_curve_field(load_curve_raw, where, params["cylinder.stroke"])
        sources["load.curve"] = load_curve_raw.get("source", "user")
    effects = effect_values(data, where)
    cfg = PlantConfig(
        name=name.strip(),
        description=str(description),
        path=None if where.startswith("<") else where,
        digest=digest,
        params=MappingProxyType(params),
        sources=MappingProxyType(sources),
        options=MappingProxyType(options),
        load_curve=load_curve,
        effects=MappingProxyType({k: MappingProxyType(v) for k, v in effects.items()}),
        provenance=MappingProxyType({str(k): str(v) for k, v in (data.get("provenance") or {}).items()}),
        identity=parse_identity(data.get("identity"), where),
        assumptions=MappingProxyType(read_assumptions(data, where, params, atmosphere_of(data, where))),
        model_evidence=parse_model_evidence(data.get("model_evidence"), where, None if where.startswith("<") else where),
        commissioning=parse_commissioning(data.get("commissioning"), where),
    )
    _check_physical(cfg, where)
    return cfg


def _check_physical(cfg: PlantConfig, where: str) -> None:
    """Cross-parameter checks that a single bound cannot express."""
    p = cfg.params
    if p["cylinder.rod_diameter"] >= p["cylinder.piston_diameter"]:
        raise InputError(f"{where}: cylinder.rod_diameter must be smaller than cylinder.piston_diameter")
    if p["air.supply_pressure"] <= p["air.atmospheric_pressure"]:
        raise InputError(
            f"{where}: air.supply_pressure ({p['air.supply_pressure']:.0f} Pa abs) must be above "
            f"air.atmospheric_pressure ({p['air.atmospheric_pressure']:.0f} Pa abs)"
        )
    for side in ("positive", "negative"):
        if p["valve.saturation_voltage"] <= p[f"valve.dead_zone_{side}"]:
            raise InputError(f"{where}: valve.saturation_voltage must exceed valve.dead_zone_{side}")
    if p["valve.command_limit"] < p["valve.saturation_voltage"]:
        raise InputError(
            f"{where}: valve.command_limit ({p['valve.command_limit']:g} V) is below valve.saturation_voltage "
            f"({p['valve.saturation_voltage']:g} V): the command could never open the valve fully, so no full-stroke "
            "speed would be the valve's; raise the limit or lower the saturation voltage")
    if p["friction.static_force"] < p["friction.coulomb_force"]:
        raise InputError(f"{where}: friction.static_force must be >= friction.coulomb_force")
    law = cfg.options["valve.flow_law"]
    need = {"sanville": "valve.effective_area", "bobrow": "valve.bobrow_coefficient", "power_law": "valve.power_law_c1"}.get(law)
    if need and p[need] <= 0.0:
        raise InputError(f"{where}: valve.flow_law = '{law}' needs {need} > 0")
    limiter = [k for k in ("controller.setpoint_opening_rate", "controller.setpoint_closing_rate", "controller.end_zone_rate")
               if p[k] > 0.0]
    if limiter and not used_by_model("controller.kp", cfg.options):  # the PID's parameters are read only when it runs
        raise InputError(f"{where}: {limiter[0]}: the set-point rate limiter is an option of the PID controller "
                         f"(controller.type = 'pid'), which this configuration does not run")
    if p["controller.end_zone_rate"] > 0.0 and not 0.0 < p["controller.end_zone_width"] < 0.5 * p["cylinder.stroke"]:
        raise InputError(f"{where}: controller.end_zone_width must be > 0 and below half the stroke when "
                         "controller.end_zone_rate is set")
    ts = p["controller.sample_time"]
    h = p["simulation.step"]
    if h > ts or abs(ts / h - round(ts / h)) > 1e-6:
        raise InputError(f"{where}: simulation.step ({h:g} s) must divide controller.sample_time ({ts:g} s) exactly")


# ----------------------------------------------------------------------------------------------
def _fmt(v: float) -> str:
    return repr(float(v))


def plant_to_toml(cfg: PlantConfig) -> str:
    """Serialise a configuration to TOML text (SI units written out, sources kept)."""
    lines = [f'name = "{cfg.name}"', f"description = {_toml_str(cfg.description)}", ""]
    if cfg.provenance:
        lines.append("[provenance]")
        for k, v in cfg.provenance.items():
            lines.append(f"{k} = {_toml_str(v)}")
        lines.append("")
    sections: dict[str, list[str]] = {}
    for k, v in cfg.options.items():
        sec, name = k.split(".", 1)
        val = v if v not in ("true", "false") else v
        sections.setdefault(sec, []).append(f"{name} = {val}" if v in ("true", "false") else f'{name} = "{val}"')
    for spec in BASE_PARAMS:
        sec, name = spec.name.split(".", 1)
        v = cfg.params[spec.name]
        src = cfg.sources.get(spec.name, "user")
        sections.setdefault(sec, []).append(f'{name} = {{ value = {_quantity(spec, v)}, source = {_toml_str(src)}'
                                            + _assumption_fields(spec, cfg.assumptions.get(spec.name)) + " }")
    for sec, rows in sections.items():
        lines.append(f"[{sec}]")
        lines.extend(rows)
        lines.append("")
    if cfg.load_curve is not None:
        xs, fs = cfg.load_curve
        lines.append("[load.curve]")
        lines.append(f'source = "{cfg.sources.get("load.curve", "user")}"')
        lines.append("position = { values = [" + ", ".join(_fmt(x) for x in xs) + '], unit = "m" }')
        lines.append("force = { values = [" + ", ".join(_fmt(f) for f in fs) + '], unit = "N" }')
        lines.append("")
    lines += _model_evidence_toml(cfg)
    lines += commissioning_toml(cfg.commissioning)
    for ename, vals in cfg.effects.items():
        eff = EFFECTS[ename]
        lines.append(f"[effects.{ename}]")
        if f"effect_{ename}" in cfg.provenance:  # where its values came from (a calibration, a diagnosis)
            lines.append(f"source = {_toml_str(cfg.provenance[f'effect_{ename}'])}")
        for p in eff.params:
            v = vals[p.name]
            lines.append(f'{p.name} = "{_fmt(v)} {p.unit}"' if p.unit else f"{p.name} = {_fmt(v)}")
        lines.append("")
    return "\n".join(lines)


def _model_evidence_toml(cfg: PlantConfig) -> list[str]:
    """The ``[model_evidence]`` table of a saved configuration (recording paths as resolved when it was read)."""
    ev = cfg.model_evidence or {}
    if not ev.get("paper") and not ev.get("recordings"):
        return []
    lines = ["[model_evidence]"]
    if ev.get("paper"):
        lines.append(f"paper = {_toml_str(ev['paper'])}")
    if ev.get("recordings"):
        rows = ["{ " + ", ".join(f"{k} = {_toml_str(v)}" for k, v in r.items()) + " }" for r in ev["recordings"]]
        lines.append("recordings = [" + ", ".join(rows) + "]")
    return lines + [""]


def _quantity(spec, v: float) -> str:
    """A parameter's SI value as the file writes it (pressures absolute)."""
    if spec.unit == "number":
        return _fmt(v)
    unit = spec.unit
    return f'"{_fmt(v)} {unit} abs"' if spec.pressure else (f'"{_fmt(v)} {unit}"' if unit else _fmt(v))


def _assumption_fields(spec, a) -> str:
    """``, range = [...], range_note = ..., derived_for = {...}`` of a parameter the file gave them (model/assumptions.py)."""
    if not a:
        return ""
    out = ""
    if a.get("range"):
        r = a["range"]
        out += f", range = [{_quantity(spec, r['low'])}, {_quantity(spec, r['high'])}], range_note = {_toml_str(r['note'])}"
    if a.get("derived_for"):
        d = a["derived_for"]
        out += (f", derived_for = {{ metric = {_toml_str(d['metric'])}, value = {_toml_str(d['value'])}, "
                f"load = {_toml_str(d['load_text'])} }}")
    return out


def _toml_str(s: str) -> str:
    return '"' + str(s).replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'


def save_plant(cfg: PlantConfig, path: str | os.PathLike, *, overwrite: bool = False) -> Path:
    """Write a configuration to ``path`` atomically; refuse to overwrite unless asked.

    The text is written to a temporary file in the same folder and moved into place, so a
    failure never leaves a half-written file. The written file is re-read to prove it loads.
    """
    path = Path(path)
    if path.exists() and not overwrite:
        raise InputError(f"{path}: exists already; choose another name (nothing was overwritten)")
    text = plant_to_toml(cfg)
    plant_from_dict(tomllib.loads(text), str(path))  # prove it round-trips before writing
    write_text_atomic(path, text)
    return path

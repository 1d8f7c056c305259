"""The hardware catalogue (TOML, schema ``govcheck-hardware/1``): options an engineer can order.

Each option belongs to a group of alternatives (servo valve, cylinder bore, supply pressure
class, air receiver) with a relative cost and the model parameters it changes; the
configuration as given is the zero-cost member of every group. Options whose effect the model
cannot represent are listed apart (``not_modelled``) with the reason, and hardware the model
represents as settings (``settings``) is searched as settings. Validated at the edge with
pydantic + pint: one :class:`InputError` naming the file and field (exit 2).
"""

from __future__ import annotations

from dataclasses import dataclass

from pydantic import BaseModel, ConfigDict, Field

from compliance.effects import EFFECTS
from compliance.errors import InputError
from compliance.files.shipped import resolve_shipped
from compliance.sweep.sizing.data_file import read_validated
from compliance.physics.valve_rating import NL_MIN, conductance_of_rating, rating_of_conductance
from compliance.model.parameters import param_handle
from compliance.units import parse_quantity

__all__ = ["Catalogue", "HardwareOption", "load_catalogue", "DEFAULT_CATALOGUE"]

DEFAULT_CATALOGUE = "default"  # the shipped catalogue (compliance/data/hardware/catalogue.toml = models/hardware-catalogue.toml)
GROUPS = ("servo_valve", "cylinder_bore", "supply_pressure", "air_receiver")
# Physical bounds of an orderable option, checked at load (our choices, with what they rest on):
MAX_VALVE_RATING = 50_000.0  # [NL/min] the largest pneumatic directional valves (ISO 5599 size 4, 1") pass ~20 000
MAX_SUPPLY_GAUGE = 16e5  # [Pa] ISO 15552 cylinders are rated 10 bar, some makes 16 bar; nothing here is rated higher
STANDARD_ATMOSPHERE = 101325.0  # [Pa] gauge supply classes are read against it at load
RATING_AGREEMENT = 0.01  # a valve's rating and a conductance given beside it must agree to 1 %


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class _OptionIn(_Strict):
    group: str
    title: str
    cost: float = Field(gt=0.0)
    sets: dict[str, str | float] = {}
    valve_rating: str | None = None
    requires_effect: str | None = None
    note: str = ""


class _Described(_Strict):
    title: str
    reason: str = ""
    how: str = ""


class _CatalogueIn(_Strict):
    schema_: str = Field(alias="schema")
    title: str = ""
    options: dict[str, _OptionIn] = {}
    settings: dict[str, _Described] = {}
    not_modelled: dict[str, _Described] = {}


@dataclass(frozen=True)
class HardwareOption:
    """One orderable option: its group, cost and the parameter values it sets (raw text until applied)."""

    name: str
    group: str
    title: str
    cost: float
    sets: tuple[tuple[str, object], ...]
    valve_rating: float | None  # NL/min
    requires_effect: str | None
    where: str

    def applies_to(self, cfg) -> str | None:
        """None when the option can be applied to ``cfg``, else why not."""
        if self.requires_effect and self.requires_effect not in cfg.effects:
            return (f"the configuration has no [effects.{self.requires_effect}] (an ideal supply is already the best "
                    "case of any receiver)")
        return None

    def values(self, cfg) -> dict:
        """Parameter path -> SI value this option sets on ``cfg`` (gauge pressures with its atmosphere)."""
        atm = cfg.params["air.atmospheric_pressure"]
        out = {}
        for path, text in self.sets:
            pp = param_handle(path, self.where)
            out[pp.path] = parse_quantity(text, pp.unit, f"{self.where}.sets.{path}", pressure=pp.pressure, atmosphere=atm)
        if self.valve_rating is not None:
            out["valve.sonic_conductance"] = conductance_of_rating(self.valve_rating, atm,
                                                                   cfg.params["valve.critical_pressure_ratio"])
        return out


@dataclass(frozen=True)
class Catalogue:
    """A validated catalogue: options by name, the hardware searched as settings, and what is not modelled."""

    path: str
    title: str
    options: tuple[HardwareOption, ...]
    settings: tuple[tuple[str, str, str], ...]  # (name, title, how)
    not_modelled: tuple[tuple[str, str, str], ...]  # (name, title, reason)

    def groups(self) -> dict:
        """Group -> options of that group, in file order."""
        out: dict = {}
        for o in self.options:
            out.setdefault(o.group, []).append(o)
        return out


def _option(name: str, raw: _OptionIn, where: str) -> HardwareOption:
    if raw.group not in GROUPS:
        raise InputError(f"{where}.group: '{raw.group}' is not one of {', '.join(GROUPS)}")
    if not raw.sets and raw.valve_rating is None:
        raise InputError(f"{where}: an option must set something (sets = {{...}} or valve_rating)")
    for path, text in raw.sets.items():
        pp = param_handle(path, f"{where}.sets")
        v = parse_quantity(text, pp.unit, f"{where}.sets.{path}", pressure=pp.pressure)
        if not pp.low <= v <= pp.high:
            raise InputError(f"{where}.sets.{path}: {v:g} {pp.unit} is outside {pp.low:g} .. {pp.high:g} ({pp.meaning})")
    rating = None
    if raw.valve_rating is not None:
        text = raw.valve_rating.replace("NL/min", "L/min")
        if text == raw.valve_rating:
            raise InputError(f"{where}.valve_rating: expected a nominal flow in NL/min (e.g. \"700 NL/min\")")
        rating = parse_quantity(text, "m^3/s", f"{where}.valve_rating") / NL_MIN
        if rating <= 0.0:
            raise InputError(f"{where}.valve_rating: must be > 0 NL/min")
    check_option_physics(raw, rating, where)
    if raw.requires_effect and raw.requires_effect not in EFFECTS:
        raise InputError(f"{where}.requires_effect: '{raw.requires_effect}' is not a declared effect "
                         f"({', '.join(sorted(EFFECTS))})")
    return HardwareOption(name, raw.group, raw.title, raw.cost, tuple(raw.sets.items()), rating, raw.requires_effect, where)


def check_option_physics(raw: _OptionIn, rating: float | None, where: str) -> None:
    """What one option sets is hardware that can exist: a rating in the range valves are made, one valve not
    described twice in contradiction, a rod thinner than its bore, a supply above atmosphere and within the
    cylinders' rating.

    Raises
    ------
    InputError
        Naming the option and the field.
    """
    values = {}
    for path, text in raw.sets.items():
        pp = param_handle(path, f"{where}.sets")
        values[pp.path] = parse_quantity(text, pp.unit, f"{where}.sets.{path}", pressure=pp.pressure,
                                         atmosphere=STANDARD_ATMOSPHERE)
    if rating is not None and rating > MAX_VALVE_RATING:
        raise InputError(f"{where}.valve_rating: {rating:.3g} NL/min; no pneumatic valve is rated above "
                         f"{MAX_VALVE_RATING:.0f} NL/min (check the unit: NL/min, not NL/h or mL/min)")
    c = values.get("valve.sonic_conductance")
    if c is not None:
        as_rating = rating_of_conductance(c, STANDARD_ATMOSPHERE)
        if rating is not None and abs(as_rating - rating) > RATING_AGREEMENT * rating:
            raise InputError(f"{where}: valve_rating = {rating:.0f} NL/min and sets.valve.sonic_conductance "
                             f"({c * 1e8:.3g} dm^3/(s*bar), i.e. {as_rating:.0f} NL/min) describe two different valves; "
                             "give one of them")
        if as_rating > MAX_VALVE_RATING:
            raise InputError(f"{where}.sets.valve.sonic_conductance: {c * 1e8:.3g} dm^3/(s*bar) is a {as_rating:.3g} NL/min "
                             f"valve; no pneumatic valve is rated above {MAX_VALVE_RATING:.0f} NL/min")
    bore, rod = values.get("cylinder.piston_diameter"), values.get("cylinder.rod_diameter")
    if bore is not None and rod is not None and not rod < bore:
        raise InputError(f"{where}.sets.cylinder.rod_diameter: a {rod * 1e3:g} mm rod on a {bore * 1e3:g} mm bore; "
                         "the rod must be thinner than the bore (ISO 15552: 125 mm bore, 32 mm rod)")
    supply = values.get("air.supply_pressure")
    if supply is not None:
        if not supply > STANDARD_ATMOSPHERE:
            raise InputError(f"{where}.sets.air.supply_pressure: {supply / 1e5:.3g} bar abs is not above atmosphere "
                             f"({STANDARD_ATMOSPHERE / 1e5:.3g} bar abs); nothing would move (write \"6 bar gauge\" "
                             "or \"7 bar abs\")")
        if supply - STANDARD_ATMOSPHERE > MAX_SUPPLY_GAUGE:
            raise InputError(f"{where}.sets.air.supply_pressure: {(supply - STANDARD_ATMOSPHERE) / 1e5:.3g} bar gauge is "
                             f"above the {MAX_SUPPLY_GAUGE / 1e5:.0f} bar gauge any ISO 15552 cylinder is rated for")


def load_catalogue(source=DEFAULT_CATALOGUE) -> Catalogue:
    """Read and validate a hardware catalogue (a TOML path, or ``"default"`` for the shipped one).

    Raises
    ------
    InputError
        Unreadable TOML, unknown field, group or parameter path, wrong unit, option that sets nothing.
    """
    path = resolve_shipped("catalogue" if source in (None, DEFAULT_CATALOGUE) else source, "hardware")
    raw = read_validated(path, _CatalogueIn, "govcheck-hardware/1", "hardware catalogue")
    opts = tuple(_option(k, v, f"{path}: options.{k}") for k, v in raw.options.items())
    return Catalogue(str(path), raw.title, opts, tuple((k, v.title, v.how) for k, v in raw.settings.items()),
                     tuple((k, v.title, v.reason) for k, v in raw.not_modelled.items()))

"""Argument helpers shared by the CLI commands (units at the edge, plant resolution)."""

from __future__ import annotations

from compliance.model.config import PlantConfig, load_plant
from compliance.errors import InputError
from compliance.units import parse_quantity


def add_plant_argument(parser, positional: bool = True) -> None:
    """Add the plant argument: a TOML path, or a reference name via --plant."""
    if positional:
        parser.add_argument("config", nargs="?", help="plant configuration file (TOML), e.g. models/plant-a.toml")
    parser.add_argument("--plant", help="plant configuration file or reference name (see 'govcheck plants')")


def plant_from_args(args) -> PlantConfig:
    """Load the plant named by a positional path or --plant."""
    src = getattr(args, "config", None) or getattr(args, "plant", None)
    if not src:
        raise InputError("no plant given: pass a configuration file (models/plant-a.toml) or --plant NAME")
    return load_plant(src)


def quantity(text: str | None, si_unit: str, option: str, default: float | None = None) -> float | None:
    """Parse a CLI quantity such as '136 mm' or '11.4 kN'; a bare number means SI."""
    if text is None:
        return default
    try:
        return float(text)
    except ValueError:
        return parse_quantity(text, si_unit, option)

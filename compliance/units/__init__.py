"""Units at the edges: one pint registry, strings with units -> SI floats, and amounts that may be
relative to the stroke. The core never sees a unit string."""

from compliance.units.quantities import ATMOSPHERE_PA, convert_array, parse_quantity, registry

__all__ = ["ATMOSPHERE_PA", "convert_array", "parse_quantity", "registry"]

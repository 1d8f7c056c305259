"""Declared optional physics: one declaration read by the simulator, linearisation, diagnosis and report.

Each effect has a name, a one-line physical meaning, parameters with SI units, defaults and
bounds, the states it adds, and the signature it leaves in recorded data. Each effect is one
module, ``compliance.effects.<name>``: its declaration, its slot constants in the compiled core
and its compiled terms; ``catalogue`` registers them in order. An effect is switched on in a
configuration with an ``[effects.NAME]`` table.
"""

from __future__ import annotations

from compliance.effects.base import Effect, Lumped, State
from compliance.effects.param import Param
from compliance.effects.catalogue import ALL_EFFECTS

EFFECTS: dict[str, Effect] = {e.name: e for e in ALL_EFFECTS}

__all__ = ["EFFECTS", "Effect", "Lumped", "Param", "State"]

"""The slot constants each effect module writes out are the indices its declaration produces.

numba freezes module-level integers into the compiled core, so the core reads an effect's
entries through plain constants in the effect's own module (``P_<SHORT>_ON``,
``P_<SHORT>_<SLOT>``, ``S_<slot>``). The layout itself is computed from the declarations in
``compliance.model.vector_slots``; a constant that disagrees with it (a typo, a new effect
without its lines) fails here with the line to write.
"""

from __future__ import annotations

import re
from pathlib import Path
from types import SimpleNamespace

import pytest

from compliance.effects import EFFECTS
from compliance.effects.base import Effect
from compliance.effects.catalogue import ALL_EFFECTS, EFFECT_MODULES, HOOKS, MODULES, compose
from compliance.model import vector_slots as vs


def _expected(name: str) -> dict[str, int]:
    """Constant name -> index, as the layout gives them for effect ``name``."""
    eff = EFFECTS[name]
    flag, slots = vs.EFFECT_SLOTS[name]
    out = {f"P_{eff.short.upper()}_ON": flag}
    out.update({f"P_{eff.short.upper()}_{p.slot.upper()}": slots[p.name] for p in eff.params})
    out.update({f"S_{s.slot}": s.index for s in eff.states})
    return out


@pytest.mark.parametrize("name", sorted(EFFECTS))
def test_written_out_slot_constants_match_the_layout(name):
    module = EFFECT_MODULES[name]
    path = Path(module.__file__).relative_to(Path(vs.__file__).parents[2])
    wrong = [f"{k} = {i}" for k, i in _expected(name).items() if getattr(module, k, None) != i]
    assert not wrong, f"{path}: write the slot constants " + "; ".join(f"`{w}`" for w in wrong)
    # and no stray constant of another layout: every P_/S_ integer the module writes is one of its own
    written = set(re.findall(r"^([PS]_[A-Z0-9_]+) = \d+", Path(module.__file__).read_text(), flags=re.M))
    assert written == set(_expected(name)), f"{path}: constants not produced by its declaration: {sorted(written - set(_expected(name)))}"


def test_every_effect_is_registered_once_under_its_module():
    assert [e.name for e in ALL_EFFECTS] == list(EFFECT_MODULES)
    assert len(set(EFFECT_MODULES)) == len(ALL_EFFECTS) == len(EFFECTS)
    for name, module in EFFECT_MODULES.items():
        assert module.__name__ == f"compliance.effects.{name}", f"effect {name} lives in {module.__name__}"


def test_a_term_for_an_unknown_hook_is_refused():
    bad = Effect(name="x", meaning="m", short="xx", params=(), states=(), signature="s", signals=(), explanation="{v}",
                 fit_grid={}, draw={}, terms={"frictoin_level": lambda: None})
    with pytest.raises(ValueError, match="effect x: terms for unknown hooks \\['frictoin_level'\\]"):
        compose("friction_level", (*MODULES, SimpleNamespace(EFFECT=bad, P_XX_ON=0)))


def test_every_declared_term_is_chained_into_its_hook():
    for name, module in EFFECT_MODULES.items():
        assert set(module.EFFECT.terms) <= set(HOOKS), name
    users = {hook: [e.name for e in ALL_EFFECTS if hook in e.terms] for hook in HOOKS}
    assert users["friction_level"] == ["pressure_dependent_friction", "position_dependent_friction"]  # declared order
    assert users["seal_leak"] == ["internal_leakage"] and users["vent_leak"] == ["external_leakage"]

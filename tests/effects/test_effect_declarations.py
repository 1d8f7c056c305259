"""Every declared effect is wired into the compiled core exactly as declared (one declaration, one slot)."""

from __future__ import annotations

import numpy as np
import pytest

from compliance.model.config import load_plant
from compliance.effects import EFFECTS
from compliance.model.vector_slots import EFFECT_SLOTS, STATE_NAMES
from compliance.model.plant_vector import parameter_vector

REQUIRED = {
    "heat_transfer", "internal_leakage", "external_leakage", "valve_dynamics", "supply_droop",
    "pressure_dependent_friction", "valve_offset", "position_dependent_load", "sensor_lag",
    "line_dynamics", "linkage_compliance",
}


def test_library_has_the_issue_names():
    assert REQUIRED <= set(EFFECTS)


@pytest.mark.parametrize("name", sorted(EFFECTS))
def test_declaration_matches_core_slots(name):
    eff = EFFECTS[name]
    flag, slots = EFFECT_SLOTS[name]
    assert set(slots) == {p.name for p in eff.params}
    for p in eff.params:
        lo, hi = p.bounds
        assert lo <= p.default <= hi, f"{name}.{p.name}: default outside bounds"
        if p.log_scale:
            assert lo > 0, f"{name}.{p.name}: log-scaled parameter needs a positive lower bound"
    assert eff.meaning and eff.signature and eff.signals
    cfg = load_plant("plant-a")
    P_off = parameter_vector(cfg)
    assert P_off[flag] == 0.0
    on = cfg.replace(effects={name: {}})
    P_on = parameter_vector(on)
    assert P_on[flag] == 1.0
    for pname, idx in slots.items():
        assert P_on[idx] == pytest.approx(eff.param(pname).default)


@pytest.mark.parametrize("name", sorted(EFFECTS))
def test_declared_states_exist(name):
    """Core states sit at their declared index; loop-held states are outside the core's vector."""
    for s in EFFECTS[name].states:
        assert STATE_NAMES[s.index] == s.name, f"{name}: state {s.name} not at its declared index {s.index}"
    for s in EFFECTS[name].loop_states:
        assert s not in STATE_NAMES, f"{name}: loop state {s} is also a core state"


def test_effect_off_costs_nothing_in_results():
    """A configuration with an effect at a neutral value gives the same trace as the base model."""
    from compliance.simulation.profiles import steps
    from compliance.simulation import Scenario
    from compliance.plants import simulate

    cfg = load_plant("plant-a")
    sc = Scenario(duration=1.5, initial_position=0.08, reference=steps("5%@0.2s", 0.08, 0.16), load=5000.0)
    base = simulate(cfg, sc)
    neutral = simulate(cfg.replace(effects={"valve_offset": {"offset": 0.0}, "position_dependent_load": {"stiffness": 0.0}}), sc)
    assert np.array_equal(base.position_true.to_numpy(), neutral.position_true.to_numpy())


def _corner_cases():
    for name, eff in sorted(EFFECTS.items()):
        for p in eff.params:
            for end in p.bounds:
                yield name, p.name, end


@pytest.mark.parametrize("name, pname, value", list(_corner_cases()))
def test_every_bound_simulates_stably(name, pname, value):
    """Each parameter at either end of its declared range stays finite at the pinned step: the
    diagnosis fits anywhere inside the bounds, so none of them may make RK4 blow up."""
    from compliance.simulation.profiles import steps
    from compliance.simulation import Scenario
    from compliance.plants import simulate

    cfg = load_plant("plant-a").replace(effects={name: {pname: value}})
    df = simulate(cfg, Scenario(duration=1.5, initial_position=0.08, reference=steps("5%@0.2s,-10%@0.8s", 0.08, 0.16), load=6000.0))
    assert np.isfinite(df[["position_true", "pressure_a", "pressure_b"]].to_numpy()).all()
    assert (df.pressure_a > 0).all() and (df.pressure_b > 0).all()

"""The tables other stages read are generated from the effect declarations, and say what they declare."""

from __future__ import annotations

import numpy as np
import pytest

import compliance.model.vector_slots as vs
from compliance.diagnosis.scoring.benchmark import ANSWER_ALIASES
from compliance.diagnosis.servo.candidates import SCAN_GRIDS, effect_candidate
from compliance.diagnosis.scoring.concealed_cases import EFFECT_RANGES, SIGNED, draw_effect_params
from compliance.diagnosis.servo.explanation import PHYSICS
from compliance.effects import EFFECTS
from compliance.errors import InputError
from compliance.linear.analysis import PADE_ORDER, _augment
from compliance.linear.trim import kept_states
from compliance.model.plant_vector import parameter_vector
from compliance.model.config import load_plant
from compliance.model.parameters import BASE_PARAMS
from compliance.model.state_feedback import controller_vector
from compliance.simulation.state_feedback_loop import AxisReference, simulate_axis

CORE = {vs.S_X, vs.S_V, vs.S_PA, vs.S_PB}


@pytest.fixture(scope="module")
def plant_a():
    return load_plant("plant-a")


def test_parameter_vector_entries_are_unique_and_named_by_the_declarations():
    assert len(set(vs.PARAM_NAMES)) == len(vs.PARAM_NAMES)
    assert len({e.short for e in EFFECTS.values()}) == len(EFFECTS)
    for name, eff in EFFECTS.items():
        flag, slots = vs.EFFECT_SLOTS[name]
        assert vs.PARAM_NAMES[flag] == f"{eff.short}_on"
        assert set(slots) == {p.name for p in eff.params}, f"{name}: a declared parameter has no slot"
        for p in eff.params:
            assert vs.PARAM_NAMES[slots[p.name]] == f"{eff.short}_{p.slot}"


def test_every_state_has_its_declared_slot():
    declared = {s.index: s for e in EFFECTS.values() for s in e.states}
    assert len(declared) == sum(len(e.states) for e in EFFECTS.values()), "two effects claim one state index"
    for i, s in declared.items():
        assert vs.STATE_NAMES[i] == s.name
    # the core's own states plus the declared ones fill the vector without gaps
    assert set(declared) | CORE | {vs.S_Z1, vs.S_Z2} == set(range(vs.N_STATES))


def test_base_parameters_fill_their_declared_slots(plant_a):
    P = parameter_vector(plant_a)
    slotted = [p for p in BASE_PARAMS if p.slot is not None]
    assert len({p.slot for p in slotted}) == len(slotted)
    for p in slotted:
        assert P[vs.PI[p.slot]] == plant_a.params[p.name], p.name


@pytest.mark.parametrize("name", sorted(EFFECTS))
def test_kept_states_are_the_declared_ones(plant_a, name):
    """Switching an effect on adds exactly its declared states to the linear model."""
    off = kept_states(parameter_vector(plant_a))
    on = kept_states(parameter_vector(plant_a.replace(effects={name: {}})))
    assert set(off) == CORE
    assert set(on) - set(off) == {s.index for s in EFFECTS[name].states}
    assert on == sorted(on)


def test_linear_model_reads_declared_delays_and_lags(plant_a):
    """A declared output lag adds one state, each declared delay a Pade approximant."""
    import control

    plant = control.ss([[0.0, 1.0], [0.0, -10.0]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]])
    assert _augment(plant_a, plant).nstates == 2
    lag = plant_a.replace(effects={"sensor_lag": {"time_constant": 0.01, "delay": 0.003}})
    assert _augment(lag, plant).nstates == 2 + 1 + PADE_ORDER
    spool = plant_a.replace(effects={"valve_dynamics": {"delay": 0.004}, "valve_offset": {}})
    assert _augment(spool, plant).nstates == 2 + PADE_ORDER  # valve_offset declares no delay: adds nothing


@pytest.fixture(scope="module")
def plant_b():
    cfg = load_plant("plant-b")
    x0 = 0.5 * cfg.p("cylinder.stroke")
    n = 11
    return cfg, AxisReference(np.full(n, x0), np.zeros(n), np.zeros(n))


@pytest.mark.parametrize("name", sorted(e.name for e in EFFECTS.values() if e.loop_states))
def test_plant_b_refuses_what_its_declaration_refuses(plant_b, name):
    cfg, ref = plant_b
    with pytest.raises(InputError, match=f"effect {name} is not supported by the tracking loop"):
        simulate_axis(cfg.replace(effects={name: {}}), ref, mode="pid")


@pytest.mark.parametrize("name", sorted(e.name for e in EFFECTS.values() if e.input_delay))
def test_plant_b_refuses_a_declared_input_delay_but_runs_without_it(plant_b, name):
    cfg, ref = plant_b
    delay = EFFECTS[name].input_delay
    with pytest.raises(InputError, match=f"a {name} delay is not supported"):
        simulate_axis(cfg.replace(effects={name: {delay: 0.004}}), ref, mode="pid")
    design = controller_vector(cfg, mode="pid", x0=float(ref.position[0]))  # designed on the plain axis
    df = simulate_axis(cfg.replace(effects={name: {delay: 0.0}}), ref, mode="pid", design=design)
    assert np.isfinite(df["position_true"].to_numpy()).all()


@pytest.mark.parametrize("name", sorted(EFFECTS))
def test_diagnosis_tables_come_from_the_declaration(name):
    eff = EFFECTS[name]
    assert PHYSICS[name] == eff.explanation and "{v}" in eff.explanation
    assert EFFECT_RANGES[name] == eff.draw
    assert (name in SIGNED) == eff.draw_signed
    declared = {p.name for p in eff.params}
    assert set(eff.fit_grid) <= declared and set(eff.draw) <= declared
    grid = SCAN_GRIDS[name]
    assert len(grid) == int(np.prod([len(v) for v in eff.fit_grid.values()]))
    for p, (lo, hi, _log) in eff.draw.items():
        blo, bhi = eff.param(p).bounds
        assert max(lo, blo) <= min(hi, bhi), f"{name}.{p}: draw range outside the declared bounds"
    for point in effect_candidate(name).grid:  # starting points lie inside the declared bounds
        for p, v in point.items():
            lo, hi = eff.param(p).bounds
            assert lo <= v <= hi
    draw = draw_effect_params(np.random.default_rng(3), name)
    for p, v in draw.items():
        lo, hi, _log = eff.draw[p]
        assert lo <= abs(v) <= hi if eff.draw_signed else lo <= v <= hi


def test_answer_aliases_are_declared_parameters():
    assert len(ANSWER_ALIASES) == sum(len(p.aliases) for e in EFFECTS.values() for p in e.params)
    for alias, key in ANSWER_ALIASES.items():
        name, pname = key.split(".", 1)
        assert alias in EFFECTS[name].param(pname).aliases
    assert ANSWER_ALIASES["td_valve"] == "valve_dynamics.delay"

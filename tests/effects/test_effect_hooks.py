"""A structural effect's rest state, trim and replay restart come from the hooks in its own module.

The callers (rest state, trim, replay) name no effect; these tests check the physics each hook
promises through those callers, and that the slot layout follows the declared slots.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from compliance.effects import EFFECTS
from compliance.effects.base import ReplayPoint
from compliance.effects.catalogue import ALL_EFFECTS
from compliance.effects.structure import reading_lags, reset_for_replay
from compliance.linear.trim import trim
from compliance.model import vector_slots as vs
from compliance.model.config import load_plant
from compliance.model.plant_vector import load_curve_arrays, parameter_vector
from compliance.model.rest_state import initial_state, load_force, pneumatic_forces


@pytest.fixture(scope="module")
def plant_a():
    return load_plant("plant-a")


def _index(name):
    return vs.STATE_INDEX[name]


def test_states_at_rest_follow_the_core(plant_a):
    """Gas at the supply temperature, reservoir at the supply pressure, hoses at their chamber's pressure."""
    cfg = plant_a.replace(effects={"heat_transfer": {}, "supply_droop": {}, "line_dynamics": {}})
    P = parameter_vector(cfg, load=5000.0)
    y = initial_state(cfg, P, 0.08)
    assert y[_index("temperature_a")] == y[_index("temperature_b")] == cfg.p("air.supply_temperature")
    assert y[_index("supply_pressure")] == cfg.p("air.supply_pressure")
    assert y[_index("line_pressure_a")] == y[vs.S_PA] and y[_index("line_pressure_b")] == y[vs.S_PB]
    # no flow at rest: the states the hooks set leave the hoses and the reservoir still
    from compliance.linear.trim import rhs
    dy = rhs(P, y, P[vs.P_UCEN], cfg)
    scale = cfg.p("air.supply_pressure")
    for name in ("supply_pressure", "line_pressure_a", "line_pressure_b"):
        assert abs(dy[_index(name)]) < 1e-6 * scale, name


def test_a_held_compliant_linkage_shares_the_friction_equally(plant_a):
    """hold: f1 + K (x2 - x) - F(x)/2 = f2 - K (x2 - x) - F(x2)/2 (both bodies carry the same friction)."""
    cfg = plant_a.replace(effects={"linkage_compliance": {"stiffness": 2e5}})
    P = parameter_vector(cfg, load="curve")
    lx, ly = load_curve_arrays(cfg)
    y = initial_state(cfg, P, 0.11, (5.2e5, 3.6e5))
    x, x2 = y[vs.S_X], y[_index("position_2")]
    f1, f2 = pneumatic_forces(P, y[vs.S_PA], y[vs.S_PB])
    link = 2e5 * (x2 - x)
    share1 = f1 + link - 0.5 * load_force(P, x, lx, ly)
    share2 = f2 - link - 0.5 * load_force(P, x2, lx, ly)
    assert x2 != x
    assert share1 == pytest.approx(share2, abs=1e-6)  # the fixed point stops at 1e-12 m, x 2e5 N/m


def test_the_trim_balances_2a1_without_friction_and_shifts_the_null(plant_a):
    """trim_balance: f1 + K (x2 - x) = F(x)/2; trim_null: the valve sees command + offset, so the null is centre - offset."""
    k = 3e5
    cfg = plant_a.replace(effects={"linkage_compliance": {"stiffness": k}, "valve_offset": {"offset": 0.2},
                                   "valve_dynamics": {}})
    op = trim(cfg, 0.12, "curve")
    P = parameter_vector(cfg, load="curve")
    lx, ly = load_curve_arrays(cfg)
    x2 = op.state[_index("position_2")]
    f1 = op.pressure_a * P[vs.P_AREA_CAP] - op.pressure_b * P[vs.P_AREA_ROD]
    assert f1 + k * (x2 - 0.12) == pytest.approx(0.5 * load_force(P, 0.12, lx, ly), abs=1e-3)
    assert op.valve_null == pytest.approx(cfg.p("valve.centre_voltage") - 0.2, abs=1e-12)
    assert op.state[_index("spool_position")] == op.valve_null  # the spool rests at the null


def test_a_replay_restart_reads_the_measured_and_carries_the_rest(plant_a):
    cfg = plant_a.replace(effects={"supply_droop": {}, "heat_transfer": {}, "linkage_compliance": {}})
    P = parameter_vector(cfg)
    y = initial_state(cfg, P, 0.05)
    simulated = {"temperature_a": 301.0, "temperature_b": 288.0, "supply_pressure": 7.6e5}
    reset_for_replay(P, y, ReplayPoint(0.02, {"supply_pressure": 7.9e5}, simulated))
    assert (y[_index("temperature_a")], y[_index("temperature_b")]) == (301.0, 288.0)  # not measured: carried over
    assert y[_index("supply_pressure")] == 7.9e5  # measured
    assert y[_index("velocity_2")] == 0.02  # 2A2 moves with 2A1
    reset_for_replay(P, y, ReplayPoint(0.0, {}, simulated))
    assert y[_index("supply_pressure")] == 7.6e5  # not recorded: carried over


def test_a_replay_restart_puts_the_hoses_at_the_chamber_pressures_it_reads(plant_a):
    """A meter-out throttle can hold chamber A above the supply: the hose takes the reading, not the rest clamp."""
    cfg = plant_a.replace(effects={"line_dynamics": {}})
    P = parameter_vector(cfg)
    y = initial_state(cfg, P, 0.05)
    above = cfg.p("air.supply_pressure") + 0.5e5
    reset_for_replay(P, y, ReplayPoint(0.0, {"pressure_a": above}, {"pressure_a": 3.0e5, "pressure_b": 4.2e5,
                                                                    "temperature_a": 293.0, "temperature_b": 293.0}))
    assert y[_index("line_pressure_a")] == above  # measured
    assert y[_index("line_pressure_b")] == 4.2e5  # not recorded (or at the transducer's full scale): carried over


def test_the_reading_lags_are_the_sensor_lag_while_it_is_on(plant_a):
    assert reading_lags(parameter_vector(plant_a)) == ()
    on = plant_a.replace(effects={"sensor_lag": {"time_constant": 0.004, "delay": 0.002}})
    assert reading_lags(parameter_vector(on)) == (0.004, 0.002)


def test_an_effect_needing_an_option_is_refused_without_it(plant_a):
    from compliance.errors import InputError

    single = plant_a.replace(options={"cylinder.arrangement": "single"}, effects={"linkage_compliance": {}})
    with pytest.raises(InputError, match="effect linkage_compliance needs cylinder.arrangement = 'tandem'"):
        parameter_vector(single)


def test_the_layout_is_computed_from_the_declared_slots():
    """Each effect's entries start at its declared slot; the core fills the rest in order; no gap, no overlap."""
    for e in ALL_EFFECTS:
        assert vs.PARAM_NAMES[e.slot] == f"{e.short}_on"
    entries = {f"{e.short}_{x}" for e in ALL_EFFECTS for x in ("on", *(p.slot for p in e.params))}
    core = [n for n in vs.PARAM_NAMES if n not in entries]
    assert tuple(core) == vs._CORE
    # a new effect at the first free index is appended; anywhere else is refused with the reason
    new = replace(EFFECTS["valve_offset"], name="new", short="nw", slot=vs.N_PARAMS)
    names = vs._layout((*ALL_EFFECTS, new), vs._CORE)
    assert names[:vs.N_PARAMS] == vs.PARAM_NAMES and names[vs.N_PARAMS:] == ("nw_on", "nw_off")
    with pytest.raises(ValueError, match="leave a gap"):
        vs._layout((*ALL_EFFECTS, replace(new, slot=vs.N_PARAMS + 1)), vs._CORE)
    with pytest.raises(ValueError, match="is taken by xf_on"):
        vs._layout((*ALL_EFFECTS, replace(new, slot=EFFECTS["position_dependent_friction"].slot)), vs._CORE)


@pytest.mark.parametrize("name", sorted(n for n, e in EFFECTS.items() if e.states))
def test_every_declared_state_has_a_scale_and_a_rest_value_or_a_loop_that_settles_it(plant_a, name):
    eff = EFFECTS[name]
    for st in eff.states:
        assert callable(st.scale) or st.scale in ("stroke", "speed", "pressure", "temperature", "command")
    cfg = plant_a.replace(effects={name: {}})
    y = initial_state(cfg, parameter_vector(cfg), 0.08)
    assert np.isfinite(y).all()
    if eff.rest is None:  # the valve's lag states: the loops settle them on their first command (assembly.settle_valve)
        assert name == "valve_dynamics"

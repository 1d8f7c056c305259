"""The ordered effect registry and the compiled hooks composed from the effects' terms.

Each effect is one module of this package: its declaration (``EFFECT``), its slot constants in
the compiled core and its compiled term functions. Registering one is its entry in ``MODULES``
below (and its name in the import above it): the order is the order of the parameter-vector
entries (``compliance.model.vector_slots``), so a new effect goes last.

Bounds are physical ranges cut where the pinned RK4 step (1 ms for plant A) would go unstable:
the fastest eigenvalue of each effect times the step stays below ~2 (RK4's limit is 2.8), e.g.
a hose node relaxes at R*T*rho0*C*w'/V, so C/V <= 3e-4; the hose conductance is bounded at
1e-7 m^3/(s*Pa) (a hose is less restrictive than the 2.33e-8 valve: an independent bench's
7e-4 m^3 hose with 4.5e-8 was outside the former 3e-8 cut), so small volumes with large
conductances (C/V > 3e-4) are admissible but diverge at the 1 ms step: the simulator reports
it, the diagnosis scores such a trial as a failed fit; linkage damping/(M/2) and regulator
refill R*T*k/V_r are cut by the same rule. A load
stiffness beyond the pneumatic spring (~1.9e5 N/m) would make the plant statically unstable;
the steepest segment of the sheet's load curve is 1.25e5 N/m.

Hooks: ``plant_rhs`` (``compliance.model.assembly``) calls each hook below once; the hook is
the chain of the terms the effects declare for it (``Effect.terms``), in declared order. A
term returns its carried values unchanged while its effect is off, so an effect that is off
costs one compiled branch. Effects that change the structure of the model (a state, a node, a
second body) are composed in ``plant_rhs`` itself from their modules' kernels.
"""

from __future__ import annotations

from numba import njit

from compliance.effects import (
    external_leakage,
    heat_transfer,
    internal_leakage,
    line_dynamics,
    linkage_compliance,
    position_dependent_friction,
    position_dependent_load,
    pressure_dependent_friction,
    sensor_lag,
    supply_droop,
    valve_dynamics,
    valve_null_flow,
    valve_offset,
)

MODULES = (  # declared order: the order of the parameter-vector entries, a new effect goes last
    heat_transfer,
    internal_leakage,
    external_leakage,
    valve_dynamics,
    supply_droop,
    pressure_dependent_friction,
    valve_offset,
    position_dependent_load,
    sensor_lag,
    line_dynamics,
    linkage_compliance,
    valve_null_flow,
    position_dependent_friction,
)
ALL_EFFECTS = tuple(m.EFFECT for m in MODULES)
EFFECT_MODULES = {m.EFFECT.name: m for m in MODULES}  # effect name -> its module (slot constants, terms)


# ---- hooks: the identity (no effect) and how two terms chain, per hook signature ------------------
@njit(cache=True, error_model="numpy", inline="always")
def _no_valve_command(P, u):
    return u


def _then_valve_command(first, second):
    @njit(error_model="numpy", inline="always")
    def both(P, u):
        return second(P, first(P, u))
    return both


@njit(cache=True, error_model="numpy", inline="always")
def _no_chamber_leaks(P, pa, pb, ta, tb, ts, patm, qin_a, hin_a, qout_a, qin_b, hin_b, qout_b):
    return qin_a, hin_a, qout_a, qin_b, hin_b, qout_b


def _then_chamber_leaks(first, second):
    @njit(error_model="numpy", inline="always")
    def both(P, pa, pb, ta, tb, ts, patm, qin_a, hin_a, qout_a, qin_b, hin_b, qout_b):
        qin_a, hin_a, qout_a, qin_b, hin_b, qout_b = first(P, pa, pb, ta, tb, ts, patm, qin_a, hin_a, qout_a, qin_b, hin_b, qout_b)
        return second(P, pa, pb, ta, tb, ts, patm, qin_a, hin_a, qout_a, qin_b, hin_b, qout_b)
    return both


@njit(cache=True, error_model="numpy", inline="always")
def _no_friction_level(P, position, mean_pressure, atmosphere, stroke, factor):
    return factor


def _then_friction_level(first, second):
    @njit(error_model="numpy", inline="always")
    def both(P, position, mean_pressure, atmosphere, stroke, factor):
        return second(P, position, mean_pressure, atmosphere, stroke, first(P, position, mean_pressure, atmosphere, stroke, factor))
    return both


@njit(cache=True, error_model="numpy", inline="always")
def _no_load_force(P, position, stroke, force):
    return force


def _then_load_force(first, second):
    @njit(error_model="numpy", inline="always")
    def both(P, position, stroke, force):
        return second(P, position, stroke, first(P, position, stroke, force))
    return both


# hook name -> (identity, chaining); what each carries:
# valve_command(P, u [V]) -> u: the command the valve acts on;
# chamber_leaks(P, p_A, p_B, T_A, T_B, T_s, p_atm, inflow, inflow*T, outflow of A, the same of B) -> the six sums
#   [kg/s, kg*K/s], pressures [Pa abs], temperatures [K];
# friction_level(P, body position [m], mean chamber pressure [Pa abs], p_atm, stroke [m], factor) -> factor on
#   the static, Coulomb and breakaway friction of that body;
# load_force(P, position [m], stroke [m], closing force [N]) -> closing force.
HOOKS = {
    "valve_command": (_no_valve_command, _then_valve_command),
    "chamber_leaks": (_no_chamber_leaks, _then_chamber_leaks),
    "friction_level": (_no_friction_level, _then_friction_level),
    "load_force": (_no_load_force, _then_load_force),
}


def compose(hook: str, effects=ALL_EFFECTS):
    """The compiled chain of the effects' terms for ``hook``, in declared order.

    Raises
    ------
    ValueError
        An effect declares a term for a hook that does not exist.
    """
    for e in effects:
        unknown = set(e.terms) - set(HOOKS)
        if unknown:
            raise ValueError(f"effect {e.name}: terms for unknown hooks {sorted(unknown)} (hooks: {', '.join(HOOKS)})")
    chain, then = HOOKS[hook]
    for e in effects:
        if hook in e.terms:
            chain = then(chain, e.terms[hook])
    return chain


VALVE_COMMAND = compose("valve_command")
CHAMBER_LEAKS = compose("chamber_leaks")
FRICTION_LEVEL = compose("friction_level")
LOAD_FORCE = compose("load_force")

"""The ordered effect registry and the compiled hooks composed from the effects' terms.

Each effect is one module of this package: its declaration (``EFFECT``), its slot constants in
the compiled core, its compiled term functions and the Python hooks of a structural effect
(``compliance.effects.structure``). Registering one is its entry in ``MODULES`` below (and its
name in the import above it); a new effect goes last, its ``slot`` after every existing
parameter-vector entry (``compliance.model.vector_slots`` computes the layout from the declarations).

Bounds are physical ranges cut where the pinned RK4 step (1 ms for plant A) would go unstable:
the fastest eigenvalue of each effect times the step stays below ~2 (RK4's limit is 2.8), e.g.
a hose node relaxes at R*T*rho0*C*w'/V, so C/V <= 3e-4; the hose conductance is bounded at
1e-7 m^3/(s*Pa) (a hose is less restrictive than the 2.33e-8 valve: an independent bench's
7e-4 m^3 hose has 4.5e-8), so small volumes with large
conductances (C/V > 3e-4) are admissible but diverge at the 1 ms step: the simulator reports
it, the diagnosis scores such a trial as a failed fit; linkage damping/(M/2) and regulator
refill R*T*k/V_r are cut by the same rule. A load
stiffness beyond the pneumatic spring (~1.9e5 N/m) would make the plant statically unstable;
the steepest segment of the sheet's load curve is 1.25e5 N/m.

Hooks: ``plant_rhs`` (``compliance.model.assembly``) calls each hook below once; the hook is
the chain of the terms the effects declare for it (``Effect.terms``), in declared order, each
term called only while its effect's flag is set, so an effect that is off costs one compiled
branch. Effects that change the structure of the model (a state, a node, a
second body) are composed in ``plant_rhs`` itself from their modules' kernels, and declare
their rest state, trim and replay restart through ``Effect`` hooks.
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


# ---- hooks: the identity (no effect) and how a term is chained behind the others, per hook signature --
# ``flag`` is the term's effect's on-flag index in the parameter vector, a compile-time constant: the
# chain calls the term only while its effect is on. Every hook carries one float: a hook carrying the
# six enthalpy sums of both chambers as a tuple made plant_rhs ~20 % slower (plant_rhs
# timed alone in a compiled loop, same load: 186-216 vs 151-174 ns per call), so the leaks are two scalar hooks.
@njit(cache=True, error_model="numpy", inline="always")
def _no_valve_command(P, u):
    return u


def _then_valve_command(first, flag, term):
    @njit(error_model="numpy", inline="always")
    def both(P, u):
        u = first(P, u)
        if P[flag] != 0.0:
            return term(P, u)
        return u
    return both


@njit(cache=True, error_model="numpy", inline="always")
def _no_seal_leak(P, pa, pb, q):
    return q


def _then_seal_leak(first, flag, term):
    @njit(error_model="numpy", inline="always")
    def both(P, pa, pb, q):
        q = first(P, pa, pb, q)
        if P[flag] != 0.0:
            return term(P, pa, pb, q)
        return q
    return both


@njit(cache=True, error_model="numpy", inline="always")
def _no_vent_leak(P, p, patm, q):
    return q


def _then_vent_leak(first, flag, term):
    @njit(error_model="numpy", inline="always")
    def both(P, p, patm, q):
        q = first(P, p, patm, q)
        if P[flag] != 0.0:
            return term(P, p, patm, q)
        return q
    return both


@njit(cache=True, error_model="numpy", inline="always")
def _no_friction_level(P, position, mean_pressure, atmosphere, stroke, factor):
    return factor


def _then_friction_level(first, flag, term):
    @njit(error_model="numpy", inline="always")
    def both(P, position, mean_pressure, atmosphere, stroke, factor):
        factor = first(P, position, mean_pressure, atmosphere, stroke, factor)
        if P[flag] != 0.0:
            return term(P, position, mean_pressure, atmosphere, stroke, factor)
        return factor
    return both


@njit(cache=True, error_model="numpy", inline="always")
def _no_load_force(P, position, stroke, force):
    return force


def _then_load_force(first, flag, term):
    @njit(error_model="numpy", inline="always")
    def both(P, position, stroke, force):
        force = first(P, position, stroke, force)
        if P[flag] != 0.0:
            return term(P, position, stroke, force)
        return force
    return both


# hook name -> (identity, chaining); what each carries:
# valve_command(P, u [V]) -> u: the command the valve acts on;
# seal_leak(P, p_A, p_B [Pa abs], flow) -> mass flow from chamber A to chamber B [kg/s];
# vent_leak(P, chamber pressure, p_atm [Pa abs], flow) -> mass flow from that chamber to atmosphere [kg/s]
#   (plant_rhs does the enthalpy bookkeeping of both: gas leaves at the chamber's temperature, air
#   drawn in from atmosphere enters at the supply temperature);
# friction_level(P, body position [m], mean chamber pressure [Pa abs], p_atm, stroke [m], factor) -> factor on
#   the static, Coulomb and breakaway friction of that body;
# load_force(P, position [m], stroke [m], closing force [N]) -> closing force.
HOOKS = {
    "valve_command": (_no_valve_command, _then_valve_command),
    "seal_leak": (_no_seal_leak, _then_seal_leak),
    "vent_leak": (_no_vent_leak, _then_vent_leak),
    "friction_level": (_no_friction_level, _then_friction_level),
    "load_force": (_no_load_force, _then_load_force),
}


def compose(hook: str, modules=MODULES):
    """The compiled chain of the effects' terms for ``hook``, in declared order.

    Each term is called only while its effect's flag (index ``Effect.slot``, ``P_<SHORT>_ON`` of its module) is set.

    Raises
    ------
    ValueError
        An effect declares a term for a hook that does not exist.
    """
    for m in modules:
        unknown = set(m.EFFECT.terms) - set(HOOKS)
        if unknown:
            raise ValueError(f"effect {m.EFFECT.name}: terms for unknown hooks {sorted(unknown)} (hooks: {', '.join(HOOKS)})")
    chain, then = HOOKS[hook]
    for m in modules:
        if hook in m.EFFECT.terms:
            chain = then(chain, m.EFFECT.slot, m.EFFECT.terms[hook])
    return chain


VALVE_COMMAND = compose("valve_command")
SEAL_LEAK = compose("seal_leak")
VENT_LEAK = compose("vent_leak")
FRICTION_LEVEL = compose("friction_level")
LOAD_FORCE = compose("load_force")

"""Index layout of the compiled core's parameter vector and state vector.

numba freezes module-level integers as compile-time constants, so the core indexes plain
float arrays with these names at no cost. ``PARAM_NAMES`` / ``STATE_NAMES`` give the same
layout to Python code (assembly, linearisation, diagnosis).
"""

from __future__ import annotations

from compliance.effects.catalogue import ALL_EFFECTS
from compliance.model.parameters import BASE_PARAMS

# ---- parameter vector ------------------------------------------------------------------------
# Entries are never renumbered: numba caches compiled kernels with these integers frozen in and
# does not notice when this module changes. Each effect declares where its entries start
# (``Effect.slot``: its flag, then its parameters in declared order); the core's entries below fill
# the other indices in order, so a new core entry is appended here and a new effect takes the first
# index after every existing entry. Base parameters fill their declared ``slot``
# (``parameters.BASE_PARAMS``); the other core entries are computed by ``parameter_vector``.
_CORE = (
    # geometry and mass
    "stroke", "area_cap", "area_rod", "dead_volume", "mass", "arrangement", "n_friction",
    # air
    "p_supply", "p_atm", "t_supply", "r_gas", "gamma", "rho0", "t0",
    # valve
    "conductance", "b_crit", "dz_pos", "dz_neg", "slope_pos", "slope_neg", "u_sat", "u_centre",
    "flow_law", "eff_area", "bobrow_coef", "pow_c1", "pow_c2", "pow_exp",
    # flow-control valves (meter-out)
    "fc_on", "fc_open", "fc_close",
    # friction
    "fr_model", "f_static", "f_coulomb", "v_stribeck", "viscous", "v_limit", "sigma0", "sigma1",
    # end stops
    "k_stop", "c_stop",
    # load
    "load_mode", "load_const",
    # controller
    "kp", "ki", "kd", "ts", "filt_hz", "lc", "cdz_pos", "cdz_neg", "cslope_pos", "cslope_neg", "u_lim",
    # piecewise Stribeck friction, seed 001 eq. (8)
    "f_breakaway", "kv_low", "v_critical", "kv_high",
    # valve dynamics stage: 0 the spool filters the command (before the dead zone), 1 the lag acts on the opening
    "vd_stage",
    # set-point rate limiter of the PID loop
    "rl_on", "rl_open", "rl_close", "rl_end_rate", "rl_end_width", "rl_lead",
)


def _layout(effects, core) -> tuple[str, ...]:
    """Entry names by index: each effect's ``<short>_on``, ``<short>_<param slot>`` from its declared
    ``slot``, the core's entries in order in the indices left free.

    Raises
    ------
    ValueError
        Two effects claim one index, or the entries leave a gap.
    """
    taken: dict[int, str] = {}
    for e in effects:
        for i, name in enumerate((f"{e.short}_on", *(f"{e.short}_{p.slot}" for p in e.params))):
            if e.slot < 0 or e.slot + i in taken:
                raise ValueError(f"effect {e.name}: entry {name} at index {e.slot + i} "
                                 + ("(no slot declared)" if e.slot < 0 else f"is taken by {taken[e.slot + i]}"))
            taken[e.slot + i] = name
    rest = iter(core)
    names = [taken[i] if i in taken else next(rest, None) for i in range(len(taken) + len(core))]
    if None in names:
        raise ValueError(f"parameter-vector entries leave a gap at index {names.index(None)}: "
                         "an effect's slot must be the first index after every existing entry")
    return tuple(names)


PARAM_NAMES = _layout(ALL_EFFECTS, _CORE)
N_PARAMS = len(PARAM_NAMES)
PI = {n: i for i, n in enumerate(PARAM_NAMES)}

P_STROKE = PI["stroke"]
P_AREA_CAP = PI["area_cap"]
P_AREA_ROD = PI["area_rod"]
P_V0 = PI["dead_volume"]
P_MASS = PI["mass"]
P_ARR = PI["arrangement"]
P_NFR = PI["n_friction"]
P_PS = PI["p_supply"]
P_PATM = PI["p_atm"]
P_TS = PI["t_supply"]
P_R = PI["r_gas"]
P_GAMMA = PI["gamma"]
P_RHO0 = PI["rho0"]
P_T0 = PI["t0"]
P_C = PI["conductance"]
P_B = PI["b_crit"]
P_DZP = PI["dz_pos"]
P_DZN = PI["dz_neg"]
P_SLP = PI["slope_pos"]
P_SLN = PI["slope_neg"]
P_USAT = PI["u_sat"]
P_UCEN = PI["u_centre"]
P_LAW = PI["flow_law"]
P_EFFA = PI["eff_area"]
P_BOB = PI["bobrow_coef"]
P_POW1 = PI["pow_c1"]
P_POW2 = PI["pow_c2"]
P_POWE = PI["pow_exp"]
P_FC_ON = PI["fc_on"]
P_FC_OPEN = PI["fc_open"]
P_FC_CLOSE = PI["fc_close"]
P_FRM = PI["fr_model"]
P_FS = PI["f_static"]
P_FC = PI["f_coulomb"]
P_VS = PI["v_stribeck"]
P_BV = PI["viscous"]
P_VLIM = PI["v_limit"]
P_SIG0 = PI["sigma0"]
P_SIG1 = PI["sigma1"]
P_KSTOP = PI["k_stop"]
P_CSTOP = PI["c_stop"]
P_LOADMODE = PI["load_mode"]
P_LOAD = PI["load_const"]
P_KP = PI["kp"]
P_KI = PI["ki"]
P_KD = PI["kd"]
P_TSAMP = PI["ts"]
P_FILT = PI["filt_hz"]
P_LC = PI["lc"]
P_CDZP = PI["cdz_pos"]
P_CDZN = PI["cdz_neg"]
P_CSLP = PI["cslope_pos"]
P_CSLN = PI["cslope_neg"]
P_ULIM = PI["u_lim"]
P_FJ = PI["f_breakaway"]
P_KV1 = PI["kv_low"]
P_VD = PI["v_critical"]
P_KV2 = PI["kv_high"]
P_VD_STAGE = PI["vd_stage"]
P_RL_ON = PI["rl_on"]
P_RL_OPEN = PI["rl_open"]
P_RL_CLOSE = PI["rl_close"]
P_RL_END_RATE = PI["rl_end_rate"]
P_RL_END_WIDTH = PI["rl_end_width"]
P_RL_LEAD = PI["rl_lead"]

# base parameter key -> index: what parameter_vector copies straight from the configuration
BASE_SLOTS = {p.name: PI[p.slot] for p in BASE_PARAMS if p.slot is not None}

# effect name -> (flag index, {param name: index}): the bridge from declarations to the core. The
# compiled code reads an effect's entries through the constants its module writes out
# (P_<SHORT>_ON, P_<SHORT>_<SLOT>, e.g. compliance.effects.valve_offset.P_VO_OFF);
# tests/effects/test_effect_slots.py checks them against this layout.
EFFECT_SLOTS: dict[str, tuple[int, dict[str, int]]] = {
    e.name: (PI[f"{e.short}_on"], {p.name: PI[f"{e.short}_{p.slot}"] for p in e.params}) for e in ALL_EFFECTS
}

# ---- state vector ----------------------------------------------------------------------------
# core states by index; effects declare theirs (name, constant suffix, fixed index)
_CORE_STATES = {0: ("position", "X"), 1: ("velocity", "V"), 2: ("pressure_a", "PA"), 3: ("pressure_b", "PB"),
                6: ("bristle_1", "Z1"), 7: ("bristle_2", "Z2")}
_STATE_SLOTS = dict(_CORE_STATES)
for _e in ALL_EFFECTS:
    for _s in _e.states:
        if _s.index in _STATE_SLOTS:
            raise ValueError(f"effect {_e.name}: state {_s.name} takes index {_s.index}, already {_STATE_SLOTS[_s.index][0]}")
        _STATE_SLOTS[_s.index] = (_s.name, _s.slot)
if sorted(_STATE_SLOTS) != list(range(len(_STATE_SLOTS))):
    raise ValueError(f"state indices must be 0..n-1 without gaps, got {sorted(_STATE_SLOTS)}")
STATE_NAMES = tuple(_STATE_SLOTS[i][0] for i in range(len(_STATE_SLOTS)))
N_STATES = len(STATE_NAMES)
STATE_INDEX = {n: i for i, n in enumerate(STATE_NAMES)}
S_X, S_V, S_PA, S_PB, S_Z1, S_Z2 = 0, 1, 2, 3, 6, 7
# an effect's states: the constants S_<slot> its module writes out (e.g. compliance.effects.heat_transfer.S_TA)

# state -> the state it copies while it does not move on its own: 2A2's bristle copies 2A1's unless an
# effect frees it (``Effect.frees``), an effect's shadowing state copies its core state while the effect is off
SHADOWS = {S_Z2: S_Z1, **{s.index: STATE_INDEX[s.shadows] for e in ALL_EFFECTS for s in e.states if s.shadows}}

# ---- auxiliary outputs of the right-hand side ---------------------------------------------------
AUX_NAMES = ("friction_force", "load_force", "flow_a", "flow_b", "opening", "pneumatic_force", "supply_flow")
N_AUX = len(AUX_NAMES)
A_FRIC, A_LOAD, A_QA, A_QB, A_OPEN, A_FP, A_QS = range(N_AUX)

"""Model assembly: base physics + switched-on effects -> one compiled right-hand side.

This is the one place where the physics functions are composed. ``plant_rhs`` is the single
source of truth used by the simulator, the linearisation (trim + Jacobian) and the
diagnosis (through the simulator). The effects' terms enter through the hooks of
``compliance.effects.catalogue`` (each the chain of the declared terms, in declared order);
effects that change the model's structure are composed here from their modules' kernels.
Its parameter vector comes from ``compliance.model.plant_vector.parameter_vector``; the
states of a servo at rest from ``compliance.model.rest_state``.
"""

from __future__ import annotations

from numba import njit

from compliance.effects.catalogue import FRICTION_LEVEL, LOAD_FORCE, SEAL_LEAK, VALVE_COMMAND, VENT_LEAK
from compliance.effects.heat_transfer import P_HT_HA, P_HT_ON, S_TA, S_TB, wall_heat_flow
from compliance.effects.line_dynamics import P_LD_COND, P_LD_ON, P_LD_VOL, S_PLA, S_PLB, hose_node
from compliance.effects.linkage_compliance import P_LK_C, P_LK_K, P_LK_ON, S_V2, S_X2, link_force
from compliance.effects.supply_droop import P_SD_COND, P_SD_ON, P_SD_VOL, S_PSUP, reservoir_pressure_rate
from compliance.effects.valve_dynamics import P_VD_ON, P_VD_WN, P_VD_Z, S_SP, S_SV, spool_acceleration
from compliance.effects.valve_null_flow import P_NF_A0, P_NF_ON, P_NF_W, leaky_openings
from compliance.model.vector_slots import (
    A_FP, A_FRIC, A_LOAD, A_OPEN, A_QA, A_QB, A_QS, P_AREA_CAP, P_AREA_ROD, P_ARR, P_B, P_BOB, P_BV, P_C,
    P_CSTOP, P_DZN, P_DZP, P_EFFA, P_FC, P_FC_CLOSE, P_FC_ON, P_FC_OPEN, P_FJ, P_FRM, P_FS, P_GAMMA, P_KSTOP,
    P_KV1, P_KV2, P_LAW, P_LOAD, P_LOADMODE, P_MASS, P_NFR, P_PATM, P_POW1, P_POW2, P_POWE, P_PS, P_R,
    P_RHO0, P_SIG0, P_SIG1, P_SLN, P_SLP, P_STROKE, P_T0, P_TS, P_UCEN, P_USAT, P_V0, P_VD, P_VD_STAGE,
    P_VLIM, P_VS, S_PA, S_PB, S_V, S_X, S_Z1, S_Z2,
)
from compliance.physics.chamber import chamber_pressure_rate, chamber_temperature_rate
from compliance.physics.friction import (
    lugre_bristle_rate,
    lugre_force,
    piecewise_stribeck_friction,
    variable_viscous_friction,
)
from compliance.physics.mechanics import (
    end_stop_force,
    interp_curve,
    single_force,
    single_volumes,
)
from compliance.physics.valve_flow import (
    bobrow_mass_flow,
    iso6358_mass_flow,
    power_law_mass_flow,
    sanville_mass_flow,
    series_conductance,
)
from compliance.physics.valve_opening import openings_from_signed, signed_opening, valve_openings

STICK_TIME_CONSTANT = 1e-3  # s; variable-viscous model: how fast a stuck body's residual speed is removed


# ----------------------------------------------------------------------------------------------
@njit(cache=True, error_model="numpy", inline="always")
def _path_flow(P, opening, throttle, p_up, p_down, t_up):
    """Signed mass flow of one valve port path under the configured flow law [kg/s]."""
    law = P[P_LAW]
    if opening <= 0.0:
        return 0.0
    if law == 0.0:
        c = P[P_C] * opening
        if throttle > 0.0:
            c = series_conductance(c, throttle)  # meter-out throttle in series (seed 000 fig. 6, 2V2/2V3)
        return iso6358_mass_flow(1.0, c, p_up, p_down, t_up, P[P_B], P[P_RHO0], P[P_T0])  # seed 000 eq. (1)
    if law == 1.0:
        return sanville_mass_flow(opening * P[P_EFFA], p_up, p_down, t_up, P[P_GAMMA], P[P_R])  # seed 001 eq. (5)
    if law == 2.0:
        return bobrow_mass_flow(P[P_BOB], opening, p_up, p_down)  # seed 001 eq. (6)
    return power_law_mass_flow(P[P_POW1], P[P_POW2], P[P_POWE], opening, p_up, p_down)  # seed 001 eq. (7), fitted form


@njit(cache=True, error_model="numpy", inline="always")
def _body_friction(P, v, z, applied, fs, fc, rise, n):
    """Friction force on one body [N] and bristle rate; ``applied`` is the net non-friction force,
    ``rise`` the effects' friction-level factor already applied to ``fs`` and ``fc``."""
    if P[P_FRM] == 0.0:
        dz = lugre_bristle_rate(v, z, P[P_SIG0], fs, fc, P[P_VS])  # LuGre (Canudas de Wit 1995)
        return n * lugre_force(v, z, dz, P[P_SIG0], P[P_SIG1], P[P_BV]), dz, False
    if P[P_FRM] == 2.0:
        fj = P[P_FJ] * rise  # the friction-level effects scale F_j like F_S and F_C
        f = n * piecewise_stribeck_friction(v, applied / n, fj, P[P_KV1], P[P_VD], P[P_KV2], P[P_VLIM])  # seed 001 eq. (8)
        stuck = abs(v) < P[P_VLIM] and abs(applied) <= n * fj
        return f, 0.0, stuck
    f = n * variable_viscous_friction(v, applied / n, fs, fc, P[P_VS], P[P_BV], P[P_VLIM])  # seed 000 eq. (7)
    stuck = abs(v) < P[P_VLIM] and abs(applied) <= n * fs
    return f, 0.0, stuck


@njit(cache=True, error_model="numpy", inline="always")
def _gate_load(P, x, load_xs, load_ys):
    """Closing force of the gate ring at position ``x`` [N]: constant or load curve, plus the effects' load terms."""
    f = interp_curve(x, load_xs, load_ys) if P[P_LOADMODE] == 1.0 else P[P_LOAD]
    return LOAD_FORCE(P, x, P[P_STROKE], f)  # the effects' load terms (position_dependent_load)


@njit(cache=True, error_model="numpy")
def valve_lag_input(P, u_valve):
    """What the valve_dynamics filter acts on: the command [V] (spool stage) or, for
    ``valve.dynamics_stage = "opening"``, the signed relative opening it asks for [-]."""
    if P[P_VD_STAGE] != 1.0:
        return u_valve
    return signed_opening(VALVE_COMMAND(P, u_valve) - P[P_UCEN], P[P_DZP], P[P_DZN], P[P_SLP], P[P_SLN], P[P_USAT])


# One compiled function on purpose: split into six inline="always" kernels it was bit-identical but
# slower (benchmarks/simulator_speed.py, same run: 2 % step 0.93 -> 1.40 ms, 30 s loop 513x -> 426x real time).
@njit(cache=True, error_model="numpy")
def plant_rhs(y, P, u_valve, load_xs, load_ys, dy, aux):
    """Right-hand side of the plant: dy/dt for state ``y`` with valve input ``u_valve``.

    Parameters
    ----------
    y : ndarray
        State vector (layout ``compliance.model.vector_slots.STATE_NAMES``).
    P : ndarray
        Parameter vector (``parameter_vector``).
    u_valve : float
        Command arriving at the valve [V] (after any delay; the spool lag is a state here).
    load_xs, load_ys : ndarray
        Load curve (position [m], closing force [N]) used when ``P[load_mode] == 1``.
    dy : ndarray
        Output: state derivatives.
    aux : ndarray
        Output: auxiliary signals (``compliance.model.vector_slots.AUX_NAMES``).
    """
    x = y[S_X]
    v = y[S_V]
    pa = y[S_PA]
    pb = y[S_PB]
    ts = P[P_TS]
    patm = P[P_PATM]
    gamma = P[P_GAMMA]
    rg = P[P_R]
    for i in range(dy.shape[0]):
        dy[i] = 0.0
    linkage = P[P_LK_ON] != 0.0 and P[P_ARR] == 0.0
    x2 = y[S_X2] if linkage else x
    v2 = y[S_V2] if linkage else v
    a_cap = P[P_AREA_CAP]
    a_rod = P[P_AREA_ROD]
    # --- geometry: volumes and their rates
    if P[P_ARR] == 0.0:
        # tandem pair, reference-plant.md decoded eqs. (4)-(5); x2 differs from x only with linkage compliance
        va = 2.0 * P[P_V0] + a_cap * x + a_rod * x2
        vb = 2.0 * P[P_V0] + a_rod * (P[P_STROKE] - x) + a_cap * (P[P_STROKE] - x2)
        dva = a_cap * v + a_rod * v2
        dvb = -a_rod * v - a_cap * v2
    else:
        va, vb = single_volumes(x, P[P_STROKE], P[P_V0], a_cap, a_rod)  # seed 001 fig. 1
        dva = a_cap * v
        dvb = -a_rod * v
    # --- valve input: spool dynamics, null offset, centre
    u = u_valve
    lag_opening = P[P_VD_ON] != 0.0 and P[P_VD_STAGE] == 1.0
    if P[P_VD_ON] != 0.0:
        dy[S_SP] = y[S_SV]
        dy[S_SV] = spool_acceleration(P[P_VD_WN], P[P_VD_Z], valve_lag_input(P, u_valve), y[S_SP], y[S_SV])
        u = y[S_SP]
    if lag_opening:
        a_pa, a_at, a_pb, a_bt = openings_from_signed(u)  # the lagged opening drives the ports directly
    else:
        u = VALVE_COMMAND(P, u)  # the effects' terms on the command the valve sees (valve_offset)
        a_pa, a_at, a_pb, a_bt = valve_openings(u - P[P_UCEN], P[P_DZP], P[P_DZN], P[P_SLP], P[P_SLN], P[P_USAT])
    if P[P_NF_ON] != 0.0:
        # the lands leak near null, driven by the command the spool sees
        u_null = (u if not lag_opening else VALVE_COMMAND(P, u_valve)) - P[P_UCEN]
        a_pa, a_at, a_pb, a_bt = leaky_openings(P[P_NF_A0], P[P_NF_W], u_null, P[P_DZP], P[P_DZN], a_pa, a_at, a_pb, a_bt)
    # --- supply, port and chamber temperatures
    ps = y[S_PSUP] if P[P_SD_ON] != 0.0 else P[P_PS]
    port_a = y[S_PLA] if P[P_LD_ON] != 0.0 else pa
    port_b = y[S_PLB] if P[P_LD_ON] != 0.0 else pb
    heat = P[P_HT_ON] != 0.0
    ta = y[S_TA] if heat else ts
    tb = y[S_TB] if heat else ts
    thr_close = P[P_FC_CLOSE] if P[P_FC_ON] != 0.0 else 0.0
    thr_open = P[P_FC_OPEN] if P[P_FC_ON] != 0.0 else 0.0
    # --- valve flows (signed, positive in the nominal direction); gas leaves a side at its temperature
    q_pa = _path_flow(P, a_pa, 0.0, ps, port_a, ts if ps >= port_a else ta)
    q_at = _path_flow(P, a_at, thr_close, port_a, patm, ta if port_a >= patm else ts)
    q_pb = _path_flow(P, a_pb, 0.0, ps, port_b, ts if ps >= port_b else tb)
    q_bt = _path_flow(P, a_bt, thr_open, port_b, patm, tb if port_b >= patm else ts)
    qva = q_pa - q_at  # net valve flow towards side A
    qvb = q_pb - q_bt
    # enthalpy bookkeeping per chamber: inflow mass, inflow mass*temperature, outflow mass
    qin_a = 0.0
    hin_a = 0.0
    qout_a = 0.0
    qin_b = 0.0
    hin_b = 0.0
    qout_b = 0.0
    if P[P_LD_ON] != 0.0:
        q_la, dp_la = hose_node(P[P_LD_COND], P[P_LD_VOL], port_a, pa, ts, ta, qva, P[P_B], P[P_RHO0], P[P_T0], rg)
        q_lb, dp_lb = hose_node(P[P_LD_COND], P[P_LD_VOL], port_b, pb, ts, tb, qvb, P[P_B], P[P_RHO0], P[P_T0], rg)
        dy[S_PLA] = dp_la
        dy[S_PLB] = dp_lb
        feeds_a = q_la
        feeds_b = q_lb
    else:
        feeds_a = qva
        feeds_b = qvb
    if feeds_a >= 0.0:
        qin_a += feeds_a
        hin_a += feeds_a * ts
    else:
        qout_a -= feeds_a
    if feeds_b >= 0.0:
        qin_b += feeds_b
        hin_b += feeds_b * ts
    else:
        qout_b -= feeds_b
    # the effects' leaks; gas leaves a chamber at its own temperature, air drawn in from atmosphere enters at T_s
    q_il = SEAL_LEAK(P, pa, pb, 0.0)  # A -> B across the piston seals
    if q_il != 0.0:
        if q_il >= 0.0:
            qout_a += q_il
            qin_b += q_il
            hin_b += q_il * ta
        else:
            qin_a -= q_il
            hin_a -= q_il * tb
            qout_b -= q_il
    q_ea = VENT_LEAK(P, pa, patm, 0.0)  # to atmosphere
    q_eb = VENT_LEAK(P, pb, patm, 0.0)
    if q_ea != 0.0 or q_eb != 0.0:
        if q_ea >= 0.0:
            qout_a += q_ea
        else:
            qin_a -= q_ea
            hin_a -= q_ea * ts
        if q_eb >= 0.0:
            qout_b += q_eb
        else:
            qin_b -= q_eb
            hin_b -= q_eb * ts
    tin_a = hin_a / qin_a if qin_a > 0.0 else ts
    tin_b = hin_b / qin_b if qin_b > 0.0 else ts
    qh_a = wall_heat_flow(P[P_HT_HA], ts, ta) if heat else 0.0  # Newton's law of cooling (heat_transfer)
    qh_b = wall_heat_flow(P[P_HT_HA], ts, tb) if heat else 0.0
    # seed 000 eqs. (4)-(5) decoded (energy equation; isentropic at T_s when heat transfer is off)
    dpa = chamber_pressure_rate(qin_a, qout_a, tin_a, ta, pa, va, dva, qh_a, gamma, rg)
    dpb = chamber_pressure_rate(qin_b, qout_b, tin_b, tb, pb, vb, dvb, qh_b, gamma, rg)
    dy[S_PA] = dpa
    dy[S_PB] = dpb
    if heat:
        dy[S_TA] = chamber_temperature_rate(ta, pa, va, dpa, dva, qin_a - qout_a, rg)
        dy[S_TB] = chamber_temperature_rate(tb, pb, vb, dpb, dvb, qin_b - qout_b, rg)
    if P[P_SD_ON] != 0.0:
        dy[S_PSUP] = reservoir_pressure_rate(P[P_SD_COND], P[P_PS], ps, q_pa + q_pb, P[P_SD_VOL], rg, ts)
    # --- forces
    p_mean = 0.5 * (pa + pb)
    rise = FRICTION_LEVEL(P, x, p_mean, patm, P[P_STROKE], 1.0)  # the effects' friction-level terms at 2A1's position
    fs = P[P_FS] * rise
    fc = P[P_FC] * rise
    # _gate_load written out on the main path: the inlined helper (its load-curve loop inside) made every
    # evaluation ~45 ns slower (benchmarks/simulator_speed.py, same run: 146-158 -> 102-107 ns per call)
    if P[P_LOADMODE] == 1.0:
        f_load = interp_curve(x, load_xs, load_ys)
    else:
        f_load = P[P_LOAD]
    f_load = LOAD_FORCE(P, x, P[P_STROKE], f_load)
    if P[P_ARR] == 0.0:
        f1 = pa * a_cap - pb * a_rod  # cylinder 2A1 (decoded seed 000 eq. 6)
        f2 = pa * a_rod - pb * a_cap  # cylinder 2A2, mounted opposite
    else:
        f1 = single_force(pa, pb, a_cap, a_rod, patm)  # seed 001 eq. (9)
        f2 = 0.0
    mass = P[P_MASS]
    if not linkage:
        fp = f1 + f2
        applied = fp - f_load + end_stop_force(x, v, P[P_STROKE], P[P_KSTOP], P[P_CSTOP])
        ff, dz, stuck = _body_friction(P, v, y[S_Z1], applied, fs, fc, rise, P[P_NFR])
        acc = -v / STICK_TIME_CONSTANT if stuck else (applied - ff) / mass  # seed 000 eq. (6)
        dy[S_X] = v
        dy[S_V] = acc
        dy[S_Z1] = dz
        dy[S_Z2] = dz
        dy[S_X2] = v
        dy[S_V2] = acc
    else:
        # two cylinders (2A1 with the sensor, 2A2) joined by a spring-damper, each with half the moving
        # mass, its own piston force and friction and its half of the gate-ring load at its own position
        fp = f1 + f2
        f_link = link_force(P[P_LK_K], P[P_LK_C], x, x2, v, v2)
        m1 = 0.5 * mass
        load1 = 0.5 * f_load
        load2 = 0.5 * _gate_load(P, x2, load_xs, load_ys)
        f_load = load1 + load2
        app1 = f1 + f_link - load1 + end_stop_force(x, v, P[P_STROKE], P[P_KSTOP], P[P_CSTOP])
        app2 = f2 - f_link - load2 + end_stop_force(x2, v2, P[P_STROKE], P[P_KSTOP], P[P_CSTOP])
        ff1, dz1, st1 = _body_friction(P, v, y[S_Z1], app1, fs, fc, rise, 1.0)
        rise2 = FRICTION_LEVEL(P, x2, p_mean, patm, P[P_STROKE], 1.0)  # at 2A2's own position
        ff2, dz2, st2 = _body_friction(P, v2, y[S_Z2], app2, P[P_FS] * rise2, P[P_FC] * rise2, rise2, 1.0)
        dy[S_X] = v
        dy[S_V] = -v / STICK_TIME_CONSTANT if st1 else (app1 - ff1) / m1
        dy[S_X2] = v2
        dy[S_V2] = -v2 / STICK_TIME_CONSTANT if st2 else (app2 - ff2) / m1
        dy[S_Z1] = dz1
        dy[S_Z2] = dz2
        ff = ff1 + ff2
    aux[A_FRIC] = ff
    aux[A_LOAD] = f_load
    aux[A_QA] = qin_a - qout_a
    aux[A_QB] = qin_b - qout_b
    aux[A_OPEN] = a_pa - a_pb
    aux[A_FP] = fp
    aux[A_QS] = q_pa + q_pb


@njit(cache=True, error_model="numpy")
def friction_level_at(P, x, pa, pb):
    """Factor [-] of the effects' friction-level terms on the static and Coulomb friction of a body at ``x`` [m],
    chamber pressures ``pa``, ``pb`` [Pa abs]: what ``plant_rhs`` applies (1.0 with no such effect on)."""
    return FRICTION_LEVEL(P, x, 0.5 * (pa + pb), P[P_PATM], P[P_STROKE], 1.0)


@njit(cache=True, error_model="numpy")
def load_terms_at(P, x, force):
    """Closing ``force`` [N] plus the effects' load terms at position ``x`` [m], as in ``plant_rhs``."""
    return LOAD_FORCE(P, x, P[P_STROKE], force)


def second_body(P, y) -> tuple[float, float, bool]:
    """(position [m], speed [m/s], linked) of cylinder 2A2 as ``plant_rhs`` sees it.

    Its own states while a compliant linkage couples the tandem pair (``linked``), else 2A1's
    (the rigid pair moves as one body; a single cylinder has no second body).
    """
    if P[P_LK_ON] != 0.0 and P[P_ARR] == 0.0:
        return y[S_X2], y[S_V2], True
    return y[S_X], y[S_V], False


@njit(cache=True, error_model="numpy")
def settle_valve(P, y, u_valve):
    """Put the valve's lag states at rest under the command ``u_valve`` [V] (in place): the spool of
    ``valve_dynamics`` where that command holds it (``valve_lag_input``); nothing while it is off."""
    if P[P_VD_ON] != 0.0:
        y[S_SP] = valve_lag_input(P, u_valve)

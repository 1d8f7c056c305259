"""The servo at rest: internal states consistent with a measured position, speed and pressures.

The LuGre bristles carry the net force and a compliant linkage its share of the load, so a
simulation (or a replay of a recording) that starts from measured pressures does not slip or
jump at t = 0. Used by the simulator, the trim and the diagnosis alike.
"""

from __future__ import annotations

import numpy as np

from compliance.effects.base import Rest
from compliance.effects.structure import at_rest, hold_at_rest
from compliance.model.config import PlantConfig
from compliance.model.plant_vector import load_curve_arrays
from compliance.model.assembly import friction_level_at, load_terms_at, second_body
from compliance.model.vector_slots import (N_STATES, P_AREA_CAP, P_AREA_ROD, P_ARR, P_BV, P_CSTOP, P_FC, P_FRM, P_FS, P_KSTOP,
                                           P_LOAD, P_LOADMODE, P_NFR, P_PATM, P_PS, P_SIG0, P_STROKE, P_TS, P_VS, S_PA, S_PB,
                                           S_X, S_Z1, S_Z2)
from compliance.physics.friction import stribeck_magnitude
from compliance.physics.mechanics import end_stop_force, single_force


def load_force(P: np.ndarray, x: float, lx: np.ndarray, ly: np.ndarray) -> float:
    """Closing force on the gate at position ``x`` [N]: constant or load curve, plus the effects' load terms.

    The same law as ``plant_rhs`` (``_gate_load``; with linkage compliance each cylinder carries half
    of it, at its own position).
    """
    f = float(np.interp(x, lx, ly)) if P[P_LOADMODE] == 1.0 else float(P[P_LOAD])
    return float(load_terms_at(P, float(x), f))


def pneumatic_forces(P: np.ndarray, pa: float, pb: float) -> tuple[float, float]:
    """Piston forces (f1, f2) [N] of the two bodies, as in ``plant_rhs``."""
    if P[P_ARR] == 0.0:
        return pa * P[P_AREA_CAP] - pb * P[P_AREA_ROD], pa * P[P_AREA_ROD] - pb * P[P_AREA_CAP]  # decoded seed 000 eq. (6)
    return single_force(pa, pb, P[P_AREA_CAP], P[P_AREA_ROD], P[P_PATM]), 0.0  # seed 001 eq. (9)


def rest_of(P: np.ndarray, y: np.ndarray, lx: np.ndarray, ly: np.ndarray) -> Rest:
    """The servo at rest as the effects' rest hooks read it: position, pressures, forces and load of ``y``."""
    # positional and unconverted: a replay builds one at every restart
    return Rest(y[S_X], y[S_PA], y[S_PB], P[P_PS], P[P_TS], P[P_STROKE], P[P_ARR] == 0.0,
                pneumatic_forces(P, y[S_PA], y[S_PB]), lambda at: load_force(P, at, lx, ly))


def set_rest_internal_states(P: np.ndarray, y: np.ndarray, lx: np.ndarray, ly: np.ndarray, v: float = 0.0) -> None:
    """Set the unmeasured mechanical states consistent with position, speed and pressures (in place).

    A servo found at rest with given pressures is held there: the net force sits in the
    static friction (LuGre bristles deflected, Canudas de Wit et al. 1995) and the effects that
    share the load take their share (``Effect.hold``: a compliant linkage). Without this a
    recording that starts from measured pressures would slip at t = 0 and a relaxed linkage under
    load would jump.

    Parameters
    ----------
    P : ndarray
        Parameter vector.
    y : ndarray
        State; reads x, p_A, p_B; writes the load-sharing states (a compliant linkage's x2) and z1, z2 (LuGre).
    lx, ly : ndarray
        Load curve (``load_curve_arrays``).
    v : float
        Speed [m/s]; sliding bristles sit at the steady deflection g(v)/sigma0.
    """
    x = y[S_X]
    rest = rest_of(P, y, lx, ly)
    f1, f2 = rest.piston_forces
    hold_at_rest(P, y, rest)  # the load-sharing states (a compliant linkage's 2A2)
    x2, _, linkage = second_body(P, y)  # the second body as plant_rhs sees it (2A1 itself when rigidly coupled)
    if not (P[P_FRM] == 0.0 and P[P_SIG0] > 0.0):
        return
    # each cylinder of a compliant linkage carries half the gate-ring load at its own position (plant_rhs)
    f_load = 0.5 * load_force(P, x, lx, ly) + 0.5 * load_force(P, x2, lx, ly) if linkage else load_force(P, x, lx, ly)
    net = f1 + f2 - f_load + end_stop_force(x, 0.0, P[P_STROKE], P[P_KSTOP], P[P_CSTOP])
    n = P[P_NFR] if not linkage else 2.0
    z = (net / n - P[P_BV] * v) / P[P_SIG0]
    for slot, at in ((S_Z1, x), (S_Z2, x2)):  # each body's friction levels at its own position (plant_rhs)
        rise = friction_level_at(P, float(at), float(y[S_PA]), float(y[S_PB]))
        g = stribeck_magnitude(v, P[P_FS] * rise, P[P_FC] * rise, P[P_VS])  # LuGre g(v), Canudas de Wit et al. 1995
        zmax = g / P[P_SIG0]
        y[slot] = min(max(z, -zmax), zmax)


def initial_state(cfg: PlantConfig, P: np.ndarray, x0: float, pressures: tuple[float, float] | None = None, *,
                  held: bool = True) -> np.ndarray:
    """State at rest at ``x0``: pressures balance the load with mean (p_s + p_atm)/2, T = T_s.

    This is the practice emulator's convention (ANSWERS.md) and the trim a test bench
    reaches after holding a position. Given ``pressures`` (p_A, p_B) [Pa abs] replace the
    balance; the effects put their states at rest (``Effect.rest``); either way the bristles and
    the load-sharing states start deflected so that the servo is held where it is
    (``set_rest_internal_states``), unless ``held`` is False (a caller that sets them itself once
    it has put the other states in place: a replay's restart).
    """
    y = np.zeros(N_STATES)
    y[S_X] = x0
    lx, ly = load_curve_arrays(cfg)
    ps, patm = P[P_PS], P[P_PATM]
    f_load = load_force(P, x0, lx, ly) if pressures is None else 0.0  # the balance's load; given pressures need none
    if pressures is not None:
        pa, pb = pressures
    elif P[P_ARR] == 0.0:
        at = P[P_AREA_CAP] + P[P_AREA_ROD]
        pa = 0.5 * (ps + patm) + 0.5 * f_load / at
        pb = 0.5 * (ps + patm) - 0.5 * f_load / at
    else:
        ac, ar = P[P_AREA_CAP], P[P_AREA_ROD]
        pa = (f_load + patm * (ac - ar) + (ps + patm) * ar) / (ac + ar)
        pb = ps + patm - pa
    lo = patm * 1.0001
    pa = min(max(pa, lo), ps)
    pb = min(max(pb, lo), ps)
    y[S_PA] = pa
    y[S_PB] = pb
    at_rest(P, y, rest_of(P, y, lx, ly))  # the effects' states at rest (gas at T_s, reservoir at p_s, ...)
    if held:
        set_rest_internal_states(P, y, lx, ly)  # held at rest: bristles carry the net force, the link its share
    return y

"""The state a replay segment starts from: the recording's measured states, the rest carried over or set by physics.

The one place outside ``effects/`` where the replay reads effect states (gas temperatures, the
second cylinder's speed, the reservoir pressure, the hoses, the sensor's lag).
"""

from __future__ import annotations

import numpy as np

from compliance.effects.heat_transfer import S_TA, S_TB
from compliance.effects.line_dynamics import P_LD_ON, S_PLA, S_PLB
from compliance.effects.linkage_compliance import S_V2
from compliance.effects.sensor_lag import P_SL_ON, P_SL_TAU, P_SL_TD
from compliance.effects.supply_droop import P_SD_ON, S_PSUP
from compliance.model.rest_state import initial_state, set_rest_internal_states
from compliance.model.vector_slots import P_STROKE, S_PA, S_PB, S_V
from compliance.simulation.rk4 import OUTPUT_COLUMNS

OUT = {name: i for i, name in enumerate(OUTPUT_COLUMNS)}


def start_state(cfg, P: np.ndarray, setup) -> np.ndarray:
    """State where the recording starts: at rest at the smoothed recorded position and the initial pressures.

    The position is the one every later segment restarts from too (``ReplaySetup.states``, a cubic
    Savitzky-Golay smoothing), not the median of the first samples: on a transducer's lattice
    (10 um against 20 um of noise) the median snaps to a lattice point, up to half a step off the
    position the servo holds, and a settled servo keeps that offset, stuck, until it moves (on a
    generated null recording the 5 um of the median tripled the first seconds' residual over the
    null replay's). The chamber pressures are the medians of the first 50 ms; the bristles carry
    the net force (``initial_state``).
    """
    return initial_state(cfg, P, min(max(float(setup.states["position"][0]), 0.0), P[P_STROKE]), setup.initial_pressures)


def _measured(setup, signal: str, k: int, previous: np.ndarray) -> float:
    """A pressure at sample ``k``: the recorded one (smoothed), or the previous segment's where it is not
    recorded or its transducer sat at its full scale there (``ReplaySetup.full_scale``)."""
    levels = setup.full_scale.get(signal)
    if signal not in setup.states or (levels is not None and setup.recorded[signal][k] in levels):
        return float(previous[k, OUT[signal]])
    return float(setup.states[signal][k])


def reset_state(cfg, P: np.ndarray, setup, k: int, previous: np.ndarray, lx, ly) -> np.ndarray:
    """State at sample ``k`` read from the recording (measured) and the previous segment (the rest).

    Measured states (position, its smoothed velocity, chamber and supply pressures) are reset;
    unmeasured ones (and a pressure its transducer could not read) are carried over from the previous segment (gas temperatures) or set by
    physics (LuGre bristle deflection from the force balance, the spool at the command, hoses at
    the chamber pressures).
    """
    st = setup.states
    x = float(st["position"][k])
    v = float(st["velocity"][k])
    if P[P_SL_ON]:
        # the recorded position is the sensor's, which trails the piston by its total lag (exactly for a
        # delay, to first order for the lag): the piston is where the reading arrives that much later
        later = setup.time[k] + P[P_SL_TAU] + P[P_SL_TD]
        x = float(np.interp(later, setup.time, st["position"]))
        v = float(np.interp(later, setup.time, st["velocity"]))
    pa, pb = (_measured(setup, s, k, previous) for s in ("pressure_a", "pressure_b"))
    y = initial_state(cfg, P, min(max(x, 0.0), P[P_STROKE]), (pa, pb))
    # a meter-out throttle holds a chamber above the supply while the load drives the piston into it:
    # the measured (or carried) pressure stands, not the rest state's clamp to the supply
    y[S_PA], y[S_PB] = pa, pb
    if P[P_LD_ON]:
        y[S_PLA], y[S_PLB] = pa, pb  # the hoses at the chamber pressures
    y[S_V] = v
    y[S_V2] = v
    y[S_TA] = previous[k, OUT["temperature_a"]]  # gas temperatures are not measured: carried over
    y[S_TB] = previous[k, OUT["temperature_b"]]
    if P[P_SD_ON]:
        y[S_PSUP] = _measured(setup, "supply_pressure", k, previous)
    set_rest_internal_states(P, y, lx, ly, v)  # bristles carry the net force, the link its share
    return y


__all__ = ["OUT", "reset_state", "start_state"]

"""The state a replay segment starts from: the recording's measured states, the rest carried over or set by physics.

The effects' own states (gas temperatures, the second cylinder's speed, the reservoir pressure,
the hoses) are restarted by their ``replay_reset`` hooks and the sensor's lag read through its
``reading_lag`` hook (``compliance.effects.structure``): this module names no effect.
"""

from __future__ import annotations

import numpy as np

from compliance.effects.base import ReplayPoint
from compliance.effects.structure import reading_lags, reset_for_replay
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


def _readable(setup, signal: str, k: int) -> bool:
    """Whether the recording read ``signal`` at sample ``k``: recorded, and its transducer not at its full
    scale there (``ReplaySetup.full_scale``); where it did not, the previous segment's value stands."""
    levels = setup.full_scale.get(signal)
    return signal in setup.states and (levels is None or setup.recorded[signal][k] not in levels)


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
    lags = reading_lags(P)
    if lags:
        # the recorded position is the sensor's, which trails the piston by its total lag (exactly for a
        # delay, to first order for the lag): the piston is where the reading arrives that much later
        later = setup.time[k]
        for lag in lags:
            later = later + lag
        x = float(np.interp(later, setup.time, st["position"]))
        v = float(np.interp(later, setup.time, st["velocity"]))
    measured = {s: float(st[s][k]) for s in st if _readable(setup, s, k)}
    simulated = dict(zip(OUTPUT_COLUMNS, previous[k].tolist()))
    pa, pb = (measured.get(s, simulated[s]) for s in ("pressure_a", "pressure_b"))
    y = initial_state(cfg, P, min(max(x, 0.0), P[P_STROKE]), (pa, pb), held=False)  # held below, once all is set
    # a meter-out throttle holds a chamber above the supply while the load drives the piston into it:
    # the measured (or carried) pressure stands, not the rest state's clamp to the supply
    y[S_PA], y[S_PB] = pa, pb
    y[S_V] = v
    # the effects' states at the restart: measured ones from the recording, the others carried over
    reset_for_replay(P, y, ReplayPoint(v, measured, simulated))
    set_rest_internal_states(P, y, lx, ly, v)  # bristles carry the net force, the link its share
    return y


__all__ = ["OUT", "reset_state", "start_state"]

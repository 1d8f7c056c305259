"""The Python-level hooks of the structural effects, composed in declared order.

An effect that adds states (or a second body) says in its own module where they sit in a servo
at rest, how they share the load, where the linear model's trim puts them and how a replay
restarts them from a recording (``Effect.rest``, ``hold``, ``trim_balance``, ``trim_null``,
``trim``, ``replay_reset``, ``reading_lag``). The callers (``compliance.model.rest_state``,
``compliance.linear.trim``, the replay) call these compositions and name no effect: each hook
is called for every declared effect, on or off, and reads its own flag.
"""

from __future__ import annotations

from compliance.effects.base import Balance, ReplayPoint, Rest
from compliance.effects.catalogue import ALL_EFFECTS

__all__ = ["at_rest", "hold_at_rest", "reading_lags", "reset_for_replay", "trim_balance", "trim_null", "trim_states"]


def at_rest(P, y, rest: Rest) -> None:
    """Every effect's states in a servo at rest (in place)."""
    for e in ALL_EFFECTS:
        if e.rest is not None:
            e.rest(P, y, rest)


def hold_at_rest(P, y, rest: Rest) -> None:
    """The states that share the load in a servo held at rest, of the effects switched on (in place)."""
    for e in ALL_EFFECTS:
        if e.hold is not None:
            e.hold(P, y, rest)


def trim_balance(P, balance: Balance):
    """The load balance of the trim an effect switched on takes over, or None (the core's own balance).

    Returns
    -------
    tuple or None
        (closing force on the actuator [N], ``balance.pressures`` of it, {state index: value}).
    """
    for e in ALL_EFFECTS:
        if e.trim_balance is not None:
            found = e.trim_balance(P, balance)
            if found is not None:
                return found
    return None


def trim_null(P, null: float) -> float:
    """The valve command at the trim [V], from the core's ``null`` through the effects' ``trim_null`` hooks."""
    for e in ALL_EFFECTS:
        if e.trim_null is not None:
            null = e.trim_null(P, null)
    return null


def trim_states(P, y, null: float) -> None:
    """The effects' states at the trim with the valve command at ``null`` [V] (in place)."""
    for e in ALL_EFFECTS:
        if e.trim is not None:
            e.trim(P, y, null)


def reset_for_replay(P, y, point: ReplayPoint) -> None:
    """The effects' states where a replay restarts a segment from a recording (in place).

    Call it after the core's states are set from the recording and before the load-sharing
    states are (``compliance.model.rest_state.set_rest_internal_states``).
    """
    for e in ALL_EFFECTS:
        if e.replay_reset is not None:
            e.replay_reset(P, y, point)


def reading_lags(P) -> tuple[float, ...]:
    """The lags [s] by which the recorded position trails the piston, of the effects switched on, in declared order.

    Empty when no such effect is on; a replay that restarts from a recording reads the piston's
    position at the recorded time plus each of them.
    """
    lags: tuple[float, ...] = ()
    for e in ALL_EFFECTS:
        if e.reading_lag is not None:
            lags += tuple(e.reading_lag(P))
    return lags

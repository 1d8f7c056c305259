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


def _declared(hook: str) -> tuple:
    """The effects' ``hook`` functions, in declared order (a replay restarts many times: looked up once)."""
    return tuple(getattr(e, hook) for e in ALL_EFFECTS if getattr(e, hook) is not None)


_REST, _HOLD, _TRIM_BALANCE, _TRIM_NULL, _TRIM = map(_declared, ("rest", "hold", "trim_balance", "trim_null", "trim"))
_REPLAY_RESET, _READING_LAG = _declared("replay_reset"), _declared("reading_lag")


def at_rest(P, y, rest: Rest) -> None:
    """Every effect's states in a servo at rest (in place)."""
    for rest_state in _REST:
        rest_state(P, y, rest)


def hold_at_rest(P, y, rest: Rest) -> None:
    """The states that share the load in a servo held at rest, of the effects switched on (in place)."""
    for hold in _HOLD:
        hold(P, y, rest)


def trim_balance(P, balance: Balance):
    """The load balance of the trim an effect switched on takes over, or None (the core's own balance).

    Returns
    -------
    tuple or None
        (closing force on the actuator [N], ``balance.pressures`` of it, {state index: value}).
    """
    for share in _TRIM_BALANCE:
        found = share(P, balance)
        if found is not None:
            return found
    return None


def trim_null(P, null: float) -> float:
    """The valve command at the trim [V], from the core's ``null`` through the effects' ``trim_null`` hooks."""
    for shift in _TRIM_NULL:
        null = shift(P, null)
    return null


def trim_states(P, y, null: float) -> None:
    """The effects' states at the trim with the valve command at ``null`` [V] (in place)."""
    for trim in _TRIM:
        trim(P, y, null)


def reset_for_replay(P, y, point: ReplayPoint) -> None:
    """The effects' states where a replay restarts a segment from a recording (in place).

    Call it after the core's states are set from the recording and before the load-sharing
    states are (``compliance.model.rest_state.set_rest_internal_states``).
    """
    for reset in _REPLAY_RESET:
        reset(P, y, point)


def reading_lags(P) -> tuple[float, ...]:
    """The lags [s] by which the recorded position trails the piston, of the effects switched on, in declared order.

    Empty when no such effect is on; a replay that restarts from a recording reads the piston's
    position at the recorded time plus each of them.
    """
    lags: tuple[float, ...] = ()
    for lag in _READING_LAG:
        lags += tuple(lag(P))
    return lags

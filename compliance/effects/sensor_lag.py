"""Sensor lag: the position transducer reports a delayed, low-passed position.

Its filter is a state of the sampled loop, not of the core: ``compliance.simulation.rk4``
(``sensor_lag_start``, ``sensor_lag_advance``) filters the sampled position exactly.
"""

from __future__ import annotations

from compliance.effects.base import Effect, Lumped
from compliance.effects.param import Param

# slots in the compiled core (tests/effects/test_effect_slots.py checks them against the layout)
P_SL_ON = 73
P_SL_TAU = 74
P_SL_TD = 75

def reading_lag(P) -> tuple[float, ...]:
    """Hook ``reading_lag``: the transducer's lag and delay [s], by which the recorded position trails the piston."""
    return (P[P_SL_TAU], P[P_SL_TD]) if P[P_SL_ON] else ()


EFFECT = Effect(
    name="sensor_lag",
    meaning="the position transducer reports a delayed, low-passed position",
    short="sl",
    slot=P_SL_ON,
    params=(
        Param("time_constant", "s", "first-order lag of the transducer", 0.005, (0.0, 0.1), slot="tau", aliases=("tau_s",)),
        Param("delay", "s", "pure delay of the transducer", 0.0, (0.0, 0.05), slot="td", aliases=("td_s",)),
    ),
    states=(),
    loop_states=("sensor_position",),  # the PID loop filters the sampled position exactly (compliance.simulation.pid_loop)
    signature="measured position lags the pressures' force; overshoot and ringing larger than modelled",
    signals=("position", "valve_command"),
    output_lag="time_constant",
    output_delay="delay",
    explanation="the position transducer reports a delayed, low-passed position (time constant {v})",
    fit_grid={"time_constant": (0.002, 0.004, 0.008, 0.015, 0.03, 0.06), "delay": (0.0, 0.002, 0.004, 0.007)},
    draw={"time_constant": (0.003, 0.03, True), "delay": (0.0, 0.004, False)},
    # phase lag of e^(-s t_d)/(1 + s tau) at w << 1/tau: w (t_d + tau)
    lumped=Lumped("total_lag", "s", "delay + time constant: the transducer's total lag as the loop sees it",
                  lambda p: p["time_constant"] + p["delay"]),
    reading_lag=reading_lag,
)

"""Which step responses measure the servo's time constant, and why the others do not.

The time constant is a small-signal figure of the positioning loop (IEC 61362:2024 data sheet;
IEEE Std 1207-2011 and the IEEE PES TR 2013 governor models keep it apart from the rate limits).
A step measures it only when no limiting device acts on it. This module decides that for one
measured step (:class:`compliance.metrics.step.StepMetrics`), simulated or recorded alike, from the
limits the test knows (:class:`StepLimits`), and says which rule excluded a step:

- **not from rest**: a step that starts where the previous one settled (``from_rest``);
- **dead-zone dominated**: its 63.2 % point lies within ``STALL_MARGIN`` x the dead-zone stall band
  of the set-point, where the compensated valve shuts;
- **ramped**: a set-point rate limiter of rate R acts on it: the set-point reaches the step h only
  after T_r = h / R, and a first-order loop following that ramp reaches 63.2 % later by
  tau ln(tau (exp(T_r / tau) - 1) / T_r) ~ T_r / 2; a ramp longer than ``RAMP_FRACTION`` of the time
  constant moves that point by more than 5 % of it: the test is no longer a step;
- **saturated**: the valve command reached the flow saturation voltage (valve fully open, or a
  meter-out flow-control valve limiting the flow) before the 63.2 % point;
- **rate limited**: its peak speed reaches ``RATE_LIMIT_FRACTION`` of the full-command peak speed,
  or its mean speed up to 63.2 % reaches that fraction of the straight-part speed of a full-command
  stroke under the same load and circuit (the flow-control valves set that speed).

Each threshold is govcheck's choice, named with the physics it stands for (docs/metrics.md).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from compliance.metrics.step import TAU_FRACTION, StepEvent, StepMetrics

__all__ = ["RAMP_FRACTION", "RATE_LIMIT_FRACTION", "STALL_MARGIN", "StepLimits", "time_constant_eligibility",
           "time_constant_value"]

# a step whose peak (or mean-to-63.2 %) speed reaches this fraction of the full-command figure is rate limited
RATE_LIMIT_FRACTION = 0.9
# a step counts for the time constant only if its 63.2 % point lies this many stall bands away from the
# set-point: closer in, the response is governed by the valve dead zone, not the loop
STALL_MARGIN = 2.0
# a set-point ramp longer than this fraction of the time constant moves the 63.2 % point by more than half that (5 %)
RAMP_FRACTION = 0.10


@dataclass(frozen=True)
class StepLimits:
    """What can limit a step, per direction (+1 = opening / up, -1 = closing / down).

    Attributes
    ----------
    stall : dict
        Dead-zone stall band [m] (``model.pid_controller.stall_error``); 0 = none.
    command_saturation : dict
        Command magnitude about the valve centre beyond which the flow stops growing [V]; None = unknown.
    ramp_rate : dict
        Rate of a set-point rate limiter acting on the steps [m/s]; 0 = none acts.
    full_speed : dict or None
        (peak, straight-part) speeds of full-command strokes under the same load and circuit [m/s].
    """

    stall: dict = field(default_factory=lambda: {+1: 0.0, -1: 0.0})
    command_saturation: dict = field(default_factory=lambda: {+1: None, -1: None})
    ramp_rate: dict = field(default_factory=lambda: {+1: 0.0, -1: 0.0})
    full_speed: dict | None = None


def time_constant_value(sm: StepMetrics, travel: str = "achieved") -> tuple[float | None, str | None]:
    """The time constant of one step by the reading ``travel`` names, and why it is missing [s].

    ``"achieved"``: end of dead time to 63.2 % of the travel the servo made (x_final - x0), the
    first-order definition; ``"commanded"``: to 63.2 % of the commanded step.
    """
    if travel == "commanded":
        return sm.time_constant, sm.reasons.get("time_constant")
    if sm.time_constant_achieved is not None:
        return sm.time_constant_achieved, None
    return None, sm.reasons.get("dead_time") or sm.reasons.get("time_constant") or "no net motion after the step"


def time_constant_eligibility(k: int, n: int, event: StepEvent, sm: StepMetrics, limits: StepLimits, *,
                              from_rest: bool = True, travel: str = "achieved") -> tuple[bool, str | None, dict]:
    """Whether step ``k`` (0-based, of ``n``) measures the time constant, why not, and the detail to report.

    Parameters
    ----------
    k, n : int
        Index of the step in its run and the number of steps.
    event, sm : StepEvent, StepMetrics
        The step and its measured response.
    limits : StepLimits
    from_rest : bool
        Only the first step of a run (from rest at the operating point) counts.
    travel : {"achieved", "commanded"}
        The reading of the time constant (:func:`time_constant_value`).

    Returns
    -------
    tuple
        (eligible, reason, detail): ``reason`` names the rule that excluded the step (``None`` when
        eligible); ``detail`` gives both readings of the time constant, the dead time, the achieved
        fraction, the peak and mean speeds and, when excluded, ``excluded`` = the rule's name.
    """
    side = 1 if event.size > 0 else -1
    h = abs(event.size)
    val, why = time_constant_value(sm, travel)
    achieved = (sm.x_final - sm.x_start) / event.size if event.size else None
    detail = {"travel": travel, "tau_commanded": sm.time_constant, "tau_achieved": sm.time_constant_achieved,
              "dead_time": sm.dead_time, "achieved_fraction": achieved, "peak_speed": sm.max_speed,
              "command_peak": sm.command_peak}

    def out(rule, reason):
        detail["excluded"] = rule
        return False, reason, detail

    if k > 0 and from_rest:
        return out("not_from_rest", f"not from rest at the operating point: step {k + 1} of {n} starts where step {k} "
                                    f"settled ({sm.x_start * 1e3:.1f} mm)")
    stall = limits.stall.get(side, 0.0)
    if stall > 0.0 and (1.0 - TAU_FRACTION) * h < STALL_MARGIN * stall:
        return out("dead_zone", f"dead-zone dominated: the 63.2 % point lies {(1 - TAU_FRACTION) * h * 1e3:.2f} mm from the "
                                f"set-point, inside {STALL_MARGIN:g} x the stall band {stall * 1e3:.2f} mm")
    rate = limits.ramp_rate.get(side, 0.0)
    if rate > 0.0:
        ramp = h / rate
        if val is None or ramp > RAMP_FRACTION * val:
            ref = "" if val is None else f", more than {RAMP_FRACTION:.0%} of the time constant it measures ({val:.3f} s)"
            return out("ramped", f"ramped: the set-point rate limiter ({rate * 1e3:.1f} mm/s) spreads this {h * 1e3:.2f} mm "
                                 f"step over {ramp:.3f} s{ref}; the 63.2 % point then follows the ramp, not the servo "
                                 "(inject the step downstream of the limiter)")
    if val is None:  # a step beyond the dead zone that never reached 63.2 %: the worst case, not a gap
        detail["non_responding"] = True
        return True, why, detail
    sat = limits.command_saturation.get(side)
    if sat is not None and sm.command_peak is not None and sm.command_peak >= sat * (1.0 - 1e-9):
        return out("saturated", f"saturated: the valve command reached {sm.command_peak:.2f} V >= the flow saturation "
                                f"{sat:.2f} V before 63.2 %")
    if limits.full_speed:
        peak, straight = limits.full_speed[side]
        moved = abs(sm.x_final - sm.x_start) if travel == "achieved" else h
        mean_speed = TAU_FRACTION * moved / val if val > 0 else float("inf")
        detail["mean_speed_to_63"] = mean_speed
        if peak > 0 and sm.max_speed >= RATE_LIMIT_FRACTION * peak:
            return out("rate_limited", f"rate limited: peak speed {sm.max_speed * 1e3:.0f} mm/s >= "
                                       f"{RATE_LIMIT_FRACTION:.0%} of the full-command speed {peak * 1e3:.0f} mm/s")
        if straight > 0 and mean_speed >= RATE_LIMIT_FRACTION * straight:
            return out("rate_limited", f"rate limited: mean speed to 63.2 % {mean_speed * 1e3:.0f} mm/s >= "
                                       f"{RATE_LIMIT_FRACTION:.0%} of the flow-control speed {straight * 1e3:.0f} mm/s "
                                       "(straight part of the full-command stroke)")
    return True, None, detail

"""A recorded sinusoid: the tracking errors after the start transient, with their uncertainty.

The errors are the simulation's (``metrics.position_error.tracking_errors``) on the conditioned
position, from ``skip_cycles`` periods after the sinusoid starts (the requirement file's sine
procedure says how many; half a period by default, ``procedures.kinds``). The largest error
carries the noise the conditioning leaves (twice: once for the sample, once for the peak a maximum
picks out of noise) and the logger filter's lag at the set-point's fastest speed.
"""

from __future__ import annotations

import math

import numpy as np

from compliance import metrics as M
from compliance.acceptance.measure.case import Case
from compliance.acceptance.measure.uncertainty import K, combine, missing, peak_bias

__all__ = ["measure_sine"]


def _start(cond, settings: dict) -> float:
    if settings.get("start_time") is not None:
        return float(settings["start_time"])
    ref = cond.column("reference")
    moving = np.nonzero(np.abs(ref - ref[0]) > 1e-6)[0]
    return float(cond.time[moving[0] - 1]) if moving.size else float(cond.time[0])


def _frequency(cond, settings: dict, t0: float) -> float | None:
    if settings.get("frequency"):
        return float(settings["frequency"])
    ref = cond.column("reference")
    seg = ref[cond.time >= t0]
    centre = float(np.median(seg))
    ups = np.nonzero((seg[:-1] < centre) & (seg[1:] >= centre))[0]
    if ups.size >= 2:
        return 1.0 / float(np.median(np.diff(cond.time[cond.time >= t0][ups])))
    return None


def measure_sine(name: str, cond, run, cfg, skip_cycles: float = 0.5, cycles_asked: float | None = None) -> list[Case]:
    """One case for a recorded sinusoid (see the module docstring)."""
    base = {"position": run.position, "load": run.load, "flow_control": run.flow_control}
    ref = cond.column("reference")
    if ref is None:
        reason = "no reference logged: the tracking error needs the set-point"
        return [Case(name, "sine", "sinusoid", base, {m: missing(reason) for m in ("tracking_max_error", "tracking_rms_error")})]
    t0 = _start(cond, run.settings)
    f = _frequency(cond, run.settings, t0)
    if not f:
        reason = "the frequency is neither stated nor readable from the reference (fewer than two periods)"
        return [Case(name, "sine", "sinusoid", base, {m: missing(reason) for m in ("tracking_max_error", "tracking_rms_error")})]
    t_from = t0 + skip_cycles / f
    run_cycles = (float(cond.time[-1]) - t0) * f
    departures = []
    if cycles_asked is not None and run_cycles < cycles_asked - 1e-6:
        departures.append(f"{run_cycles:.2f} periods run where the procedure asks {cycles_asked:g}: the errors are taken over "
                          f"{max(0.0, run_cycles - skip_cycles):.2f} periods after the first {skip_cycles:g}")
    if t_from >= float(cond.time[-1]):
        reason = f"the recording ends before {skip_cycles:g} periods of the sinusoid have passed"
        return [Case(name, "sine", "sinusoid", base, {m: missing(reason) for m in ("tracking_max_error", "tracking_rms_error")},
                     tuple(departures))]
    rms, mx = M.tracking_errors(cond.time, cond.position, ref, t_from)
    amplitude = run.settings.get("amplitude") or 0.5 * float(np.ptp(ref[cond.time >= t0]))
    lag = 2.0 * math.pi * f * amplitude * cond.filter_delay  # the filter's lag at the fastest set-point speed
    values = {
        "tracking_max_error": combine(mx, {
            "noise left after conditioning": K * cond.u_position, "logger filter": lag,
            "noise peak of a maximum": peak_bias(cond.u_position, float(cond.time[-1]) - t_from, max(cond.window, cond.dt))}),
        "tracking_rms_error": combine(rms, {"noise left after conditioning": K * cond.u_position, "logger filter": lag}),
    }
    conditions = {**base, "frequency": f, "amplitude": amplitude, "start": t0, "cycles": run_cycles, "skip_cycles": skip_cycles}
    return [Case(name, "sine", f"sinusoid {amplitude * 1e3:.1f} mm at {f:g} Hz (after {t_from:.1f} s)", conditions, values,
                 tuple(departures), {"tracking_window": [t_from, float(cond.time[-1])]})]

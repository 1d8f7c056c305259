"""The ``hold`` procedure: reach the operating point's position from below, then hold it under its load.

Starting ``approach`` below the position makes the servo move to hold it (larger than the
accuracy asked); the metrics are taken over the window after ``settle``.
"""

from __future__ import annotations

from compliance import metrics as M
from compliance.errors import InputError
from compliance.procedures.scenarios import add_drive_samples, closed_loop_trace, start_position, stroke
from compliance.procedures.outcomes import Sample

__all__ = ["run_hold"]


def run_hold(cfg, proc, op, requests, out):
    """Run a ``hold`` procedure at ``op`` and add its samples to ``out`` (see ``procedures.run``)."""
    s = proc.settings
    x0 = start_position(cfg, op, proc)
    dur, settle = s["duration"].value, s["settle"].value
    if settle >= dur:
        raise InputError(f"procedure '{proc.name}': settle ({settle:g} s) must be shorter than duration ({dur:g} s)")
    from compliance.simulation.profiles import Profile

    start = max(0.0, x0 - s["approach"].resolve(stroke(cfg)))
    label, tt, x, r, u = closed_loop_trace(cfg, proc, op, out, dur, start, Profile.constant(x0))
    if start != x0:
        out.notes.append(f"approached from {start*1e3:.1f} mm to {x0*1e3:.1f} mm")
    h = M.hold(tt, x, r, settle, dur + 1.0)
    lab = f"window {settle:g}-{dur:g} s"
    for k in ("steady_state_error", "max_positioning_error", "drift", "limit_cycle_amplitude"):
        out.add(k, Sample(getattr(h, k), lab))
    out.marks.append({"trace": label, "type": "hold_window", "value": [settle, dur]})
    add_drive_samples(cfg, out, tt, x, u, label, settle)

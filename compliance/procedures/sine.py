"""The ``sine`` procedure: track x0 + A sin(2 pi f t) in closed loop (seed 000: 8 mm at 0.05 Hz).

Tracking errors are taken after ``skip_cycles`` periods, leaving out the start transient.
"""

from __future__ import annotations

from compliance import metrics as M
from compliance.procedures.scenarios import add_drive_samples, closed_loop_trace, swing
from compliance.procedures.outcomes import Sample

__all__ = ["run_sine"]


def run_sine(cfg, proc, op, requests, out):
    """Run a ``sine`` procedure at ``op`` and add its samples to ``out`` (see ``procedures.run``)."""
    from compliance.simulation.profiles import sine

    s = proc.settings
    x0, amp = swing(cfg, proc, op)
    f = s["frequency"].value
    duration = s["cycles"] / f
    label, tt, x, r, u = closed_loop_trace(cfg, proc, op, out, duration, x0, sine(amp, f, x0, duration=duration))
    t_from = s["skip_cycles"] / f
    rms, mx = M.tracking_errors(tt, x, r, t_from)
    lab = f"after {t_from:.1f} s"
    out.add("tracking_rms_error", Sample(rms, lab))
    out.add("tracking_max_error", Sample(mx, lab))
    out.marks.append({"trace": label, "type": "tracking_window", "value": [t_from, float(tt[-1])]})
    add_drive_samples(cfg, out, tt, x, u, label)

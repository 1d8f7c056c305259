"""The ``dead_band`` procedure: a slow triangular set-point in closed loop; width of the hysteresis loop.

The set-point goes x0 -> x0+a -> x0-a -> x0+a -> x0 at ``rate``, slow against the servo's
time constant, so the loop (``metrics.dead_band``) shows the band of command change without
position change (IEC 60308), not the dynamics.
"""

from __future__ import annotations

import numpy as np

from compliance import metrics as M
from compliance.errors import InputError
from compliance.procedures.scenarios import add_drive_samples, closed_loop_trace, swing
from compliance.procedures.outcomes import Sample

__all__ = ["run_dead_band"]


def run_dead_band(cfg, proc, op, requests, out):
    """Run a ``dead_band`` procedure at ``op`` and add its samples to ``out`` (see ``procedures.run``)."""
    from compliance.simulation.profiles import Profile

    s = proc.settings
    x0, a = swing(cfg, proc, op)
    rate = s["rate"].value
    lead = s["lead"].value
    if rate <= 0:
        raise InputError(f"procedure '{proc.name}': rate must be > 0")
    leg = a / rate
    # x0 -> x0+a -> x0-a -> x0+a -> x0 : the middle two legs give both branches from a reversal
    times = np.array([0.0, lead, lead + leg, lead + 3 * leg, lead + 5 * leg, lead + 6 * leg])
    values = np.array([x0, x0, x0 + a, x0 - a, x0 + a, x0])
    label, tt, x, r, u = closed_loop_trace(cfg, proc, op, out, times[-1] + 1.0, x0, Profile(times, values))
    db = M.dead_band(tt, x, r)
    # the widest level is the worst case a verdict needs; the median is the loop's typical width (both reported)
    out.add("dead_band", Sample(db.width_max, f"widest of {db.levels} levels", detail={"median": db.width, "max": db.width_max}))
    out.add("dead_band", Sample(db.width, f"median over {db.levels} levels", detail={"median": db.width, "max": db.width_max}))
    add_drive_samples(cfg, out, tt, x, u, label)

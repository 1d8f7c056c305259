"""Which standard test a trace shows, read from the trace itself.

A commissioning log does not always say what it is. The five tests leave different marks:

- a full stroke: no set-point, the valve command jumps from one side of its centre to the other
  and the position runs across most of the stroke;
- a dead-band staircase: a set-point that moves in many equal small stairs (at most 0.25 % of
  the stroke each), both ways;
- a step series: a set-point that jumps by larger steps;
- a sinusoid: a set-point that moves every sample, up and down, without jumps;
- a hold: a set-point that stays put (the valve command settling at its centre from some time on
  is a hold with the positioner in manual).

The same reading checks a sidecar's word: a recording whose sidecar says one kind and whose
trace shows another is not judged as either (``disagreement``).
"""

from __future__ import annotations

import numpy as np

from compliance import metrics as M

__all__ = ["disagreement", "recognise"]

STAIR_SHARE = 0.0025  # a set-point change of at most this share of the stroke is a stair (0.4 mm of 160 mm)
STROKE_SHARE = 0.5  # a full stroke runs across at least this share of the stroke
NULL_SPREAD = 0.05  # V; a valve command this steady about its centre is held at null (manual)


def _jumps(cond) -> list:
    ref = cond.column("reference")
    return [] if ref is None else M.find_steps(cond.time, ref, min_size=5e-6)


def _null_from(cond, centre: float) -> float | None:
    u = cond.column("valve_command")
    if u is None:
        return None
    dev = np.abs(u - centre)
    still = dev <= NULL_SPREAD
    if not still[-1]:
        return None
    k = np.nonzero(~still)[0]
    i = 0 if k.size == 0 else int(k[-1]) + 1
    return float(cond.time[i]) if cond.time[-1] - cond.time[i] >= 1.0 else None


def recognise(cond, stroke: float, centre: float) -> tuple[str | None, str, dict]:
    """The test kind a trace shows, how it shows it, and the settings read from it.

    Returns
    -------
    (str or None, str, dict)
        ``step_series`` / ``full_stroke`` / ``dead_band_staircase`` / ``sine`` / ``hold``, or None when
        the trace shows none of them; a sentence saying why; settings (``direction``,
        ``valve_null_from``, ``stair``) read from the trace.
    """
    x = cond.position
    travel = float(np.max(x) - np.min(x))
    ref = cond.column("reference")
    u = cond.column("valve_command")
    if ref is None:
        if u is not None and travel >= STROKE_SHARE * stroke and np.sign(u[0] - centre) != np.sign(u[-1] - centre):
            direction = "opening" if x[-1] > x[0] else "closing"
            return "full_stroke", (f"no set-point; the valve command crosses its centre and the position runs "
                                   f"{travel * 1e3:.0f} mm ({direction})"), {"direction": direction}
        return None, f"no set-point and no stroke (the position moves {travel * 1e3:.1f} mm)", {}
    jumps = _jumps(cond)
    sizes = np.array([abs(e.size) for e in jumps])
    moving = np.count_nonzero(np.abs(np.diff(ref)) > 0) / max(1, ref.size - 1)
    if moving > 0.5:
        return "sine", f"the set-point moves on {100 * moving:.0f} % of the samples without jumps", {}
    stairs = sizes[sizes <= STAIR_SHARE * stroke] if sizes.size else sizes
    if stairs.size >= 6 and any(e.size > 0 for e in jumps) and any(e.size < 0 for e in jumps):
        stair = float(np.median(stairs))
        return "dead_band_staircase", f"{stairs.size} set-point stairs of {stair * 1e3:.2g} mm both ways", {"stair": stair}
    if sizes.size:
        return "step_series", (f"{sizes.size} set-point steps of {', '.join(f'{s * 1e3:.1f}' for s in sorted(set(np.round(sizes, 5))))} mm"), {}
    null = _null_from(cond, centre)
    if null is not None:
        return "hold", f"a steady set-point, the valve command at its centre from {null:.2f} s (positioner in manual)", {"valve_null_from": null}
    return "hold", "a steady set-point held in closed loop", {}


def disagreement(stated: str, seen: str | None, how: str) -> str | None:
    """Why a sidecar's kind and the trace disagree (None when they agree or the trace shows nothing clear)."""
    if seen is None or seen == stated:
        return None
    return (f"its sidecar says {stated.replace('_', ' ')} but its trace shows a {seen.replace('_', ' ')} ({how}); "
            "judged as neither - correct the sidecar's [test] kind")

"""Where a replay restarts from the recording: re-synchronised segments (multiple shooting) and the loop's mode switch.

A servo with a dead zone and stiction decides where it stalls on tiny differences, so one long
replay of a slightly wrong model wanders off for seconds and its residual becomes a rugged
function of the parameters (local minima every few per cent). The diagnosis therefore cuts the
replay into segments that each start from the *recorded* state (multiple shooting, Bock & Plitt
1984): at rest just before each set-point change, and every ``MAX_SEGMENT`` seconds otherwise.
On the practice valve-dynamics recording this turns a landscape with a dozen local minima into
one bowl. The validation replays the recording in one piece.

Either way a segment starts where the loop changes mode: a hold test's positioner switched to
manual (``replay_conditions.command_from_of``) leaves the recorded valve command driving the plant
from then on, so the closed-loop part and the command-driven part are separate segments, the
second starting from the recorded state (at rest, held by the loop just before).
"""

from __future__ import annotations

import numpy as np

MAX_SEGMENT = 2.0  # s; longest stretch replayed without re-synchronising
MIN_SEGMENT = 0.5  # s; a set-point change closer than this to the last reset does not start a new segment
PRE_STEP = 0.1  # s; a segment starts this long before a set-point change (the servo is still at rest)


def segment_starts(time: np.ndarray, reference: np.ndarray, speed: np.ndarray | None = None,
                   max_segment: float = MAX_SEGMENT) -> np.ndarray:
    """Sample indices where a re-synchronised segment starts.

    A segment starts ``PRE_STEP`` before each set-point change (the servo is at rest then),
    unless the last start is less than ``MIN_SEGMENT`` ago. A stretch longer than
    ``max_segment`` without one is cut where the recorded speed is lowest (a stuck or slow
    moment, whose state the recording gives best).
    """
    n = time.size
    dt = float(np.median(np.diff(time))) if n > 1 else 1.0
    jumps = np.flatnonzero(np.abs(np.diff(reference)) > 1e-9)
    jump_set = set(jumps.tolist())
    # a continuous profile (sine, ramp) changes every sample: only isolated changes count as steps
    steps = [k for k in jumps if not (k - 1 in jump_set and k + 1 in jump_set)]
    pre = int(round(PRE_STEP / dt))
    gap = int(round(MIN_SEGMENT / dt))
    longest = max(int(round(max_segment / dt)), 2 * gap)
    spd = np.zeros(n) if speed is None else np.abs(np.asarray(speed, dtype=float))

    def cut(a: int, b: int) -> int:
        """Quietest sample in [a + gap, min(a + longest, b - gap)]."""
        lo, hi = a + gap, min(a + longest, b - gap)
        if hi <= lo:
            return a + longest
        return lo + int(np.argmin(spd[lo:hi + 1]))

    starts = [0]
    for c in sorted(set(max(k + 1 - pre, 0) for k in steps)) + [n - 1 + gap]:
        while c - starts[-1] > longest:
            starts.append(cut(starts[-1], c))
        if c - starts[-1] >= gap and c < n - 1:
            starts.append(c)
    return np.array(starts, dtype=int)


def plan_segments(time: np.ndarray, reference: np.ndarray, command: np.ndarray, speed: np.ndarray | None,
                  command_from: int, segmented: bool, max_segment: float = MAX_SEGMENT) -> np.ndarray:
    """Start index of every segment of a replay (the first is 0).

    Parameters
    ----------
    time : ndarray
        Controller grid from 0 [s].
    reference, command : ndarray
        Set-point [m] (drives the closed-loop part) and recorded valve command [V] (the rest).
    speed : ndarray or None
        Recorded speed [m/s] (where a long stretch is cut).
    command_from : int
        First sample the valve command drives (0: all of it; ``time.size``: none).
    segmented : bool
        Re-synchronise at set-point (or command) changes and every ``max_segment``; otherwise only
        the mode switch starts a segment.
    """
    n = time.size
    switch = [command_from] if 0 < command_from < n - 1 else []
    if not segmented:
        return np.array([0] + switch, dtype=int)
    parts = []
    for a, b, drive in ((0, min(command_from, n), reference), (command_from, n, command)):
        if b - a < 2:
            continue
        sub = segment_starts(time[a:b] - time[a], drive[a:b], None if speed is None else speed[a:b], max_segment)
        parts.append(sub + a)
    return np.unique(np.concatenate(parts)).astype(int) if parts else np.array([0], dtype=int)


__all__ = ["MAX_SEGMENT", "MIN_SEGMENT", "PRE_STEP", "plan_segments", "segment_starts"]

"""Effects defined where the data is: a recording's stated load holds at its own start position.

A recording's sidecar gives the load *there*, at the operating point the test starts from. The
core's ``position_dependent_load`` adds its stiffness about mid-stroke (compliance/model/assembly.py),
so switched on in a replay of a test that starts elsewhere it would also shift the load at the
start by k (x0 - stroke/2), and no stiffness could fit both the load and its slope (issue 13:
an effect anchored at a fixed point). Every replay, null recording and predicted test of the
diagnosis therefore passes the constant load through ``load_at_start``: the constant part is
set so that the total load at the start position is the stated one, and the stiffness acts
about the recording's own operating point.
"""

from __future__ import annotations

from compliance.effects import EFFECTS

LOAD_EFFECT = "position_dependent_load"


def load_at_start(cfg, load, x0: float):
    """Constant load [N] to hand the core so that its total load at ``x0`` is ``load``.

    Parameters
    ----------
    cfg : PlantConfig
        Configuration (with any effects switched on).
    load : float or "curve"
        The recording's stated load at its start position [N] (a load curve is left alone).
    x0 : float
        Start position [m].
    """
    if isinstance(load, str) or load is None or LOAD_EFFECT not in cfg.effects:
        return load
    k = dict(EFFECTS[LOAD_EFFECT].defaults(), **cfg.effects[LOAD_EFFECT])["stiffness"]
    return float(load) - k * (float(x0) - 0.5 * cfg.p("cylinder.stroke"))  # assembly.py: k (x - stroke/2)


__all__ = ["load_at_start", "LOAD_EFFECT"]

"""How candidates are ranked: failing mandatory requirements first, then total shortfall, then cost.

A mandatory requirement counts as passing only when its status is ``pass`` and its basis is not
``by_construction`` (the verdict work marks a pass that a tuned or derived parameter makes true by
construction, and adds ``uncertain``: neither is a pass here; read with ``.get()`` so rows
without a basis work alike). Ordering lexicographically by (number of failing mandatory
requirements, total shortfall, cost) means a candidate that fails more mandatory requirements
than another never ranks above it, however close its worst one comes: the configuration as
given is always among the ranked, so the best never fails more than it.
"""

from __future__ import annotations

import math

from compliance.requirements.verdict import Basis, Severity, Status
from compliance.sweep.candidates.evaluate import judged

__all__ = ["SETTINGS_COST", "candidate_passes", "failing_mandatory", "rank_key", "requirement_passes"]

# cost of moving the settings across the whole of their declared box (normalised change 1):
# a tenth of the cheapest catalogue option, so any hardware outranks a pure settings change (our choice)
SETTINGS_COST = 0.05


def requirement_passes(r: dict) -> bool:
    """A judged requirement row passes: status pass, and not by construction."""
    return r.get("status") == Status.PASS and r.get("basis") != Basis.BY_CONSTRUCTION


def failing_mandatory(row: dict) -> list[str]:
    """Mandatory requirements of a candidate's row that do not pass (open and disabled ones aside)."""
    if not judged(row):
        return ["<invalid>"]
    return sorted(rid for rid, r in row["requirements"].items()
                  if r.get("severity") == Severity.MANDATORY and r.get("status") not in (Status.OPEN, Status.DISABLED)
                  and not requirement_passes(r))


def candidate_passes(row: dict) -> bool:
    """Every mandatory requirement passes (and at least one was judged)."""
    return judged(row) and not failing_mandatory(row)


def _total_shortfall(row: dict) -> float:
    total = 0.0
    for r in row["requirements"].values():
        if r.get("severity") != Severity.MANDATORY or r.get("status") in (Status.OPEN, Status.DISABLED) or requirement_passes(r):
            continue
        m = r.get("margin_pct")
        total += max(0.0, -m / 100.0) if m is not None else 1.0  # not evaluated: a full limit short
    return total


def rank_key(row: dict, cost: float) -> tuple:
    """Sort key (smaller is better): (failing mandatory count, total shortfall, cost)."""
    if not judged(row):
        return (math.inf, math.inf, cost)
    return (len(failing_mandatory(row)), round(_total_shortfall(row), 4), cost)

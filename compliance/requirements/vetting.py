"""A requirement set vetted once, before any simulation: loosened limits and limits that cannot hold together.

Both questions depend on the set and the plant's stroke only, so they are answered once per check
(``compliance.pipeline.chain``; ``run_campaign`` for a library caller), never again downstream:

- every inherited requirement may only be tightened unless its file says ``allow_loosen``
  (:func:`compliance.requirements.tightening.check_tightening`); an allowed loosening is a note;
- every pair of limits is checked for conflicts, tensions and narrowings
  (:func:`compliance.requirements.consistency.consistency_findings`); a conflict between two
  mandatory requirements is invalid input unless the caller allows it.
"""

from __future__ import annotations

from dataclasses import dataclass

from compliance.requirements.consistency import check_consistency
from compliance.requirements.tightening import check_tightening

__all__ = ["Vetting", "vet"]


@dataclass(frozen=True)
class Vetting:
    """What vetting a requirement set found.

    Attributes
    ----------
    findings : tuple of dict
        Conflicts, tensions, narrowings and rate splits (``consistency_findings``), for the results.
    loosened : dict
        Requirement id -> its ``LOOSENED: ...`` notes (files that widened it with ``allow_loosen``).
    """

    findings: tuple
    loosened: dict

    @property
    def notes(self) -> list[str]:
        """Every loosening note, in file order (the results' ``summary.notes``)."""
        return [n for notes in self.loosened.values() for n in notes]


def vet(reqset, stroke: float, allow_conflicts: bool = False) -> Vetting:
    """Check ``reqset`` for loosening and conflicts at this plant's ``stroke`` [m].

    Raises
    ------
    InputError
        A file loosens an inherited requirement without ``allow_loosen``, or two mandatory
        requirements no servo can pass together (unless ``allow_conflicts``).
    """
    loosened = {req.id: check_tightening(req, stroke) for req in reqset.requirements}
    findings = check_consistency(reqset, stroke, allow_conflicts)
    return Vetting(tuple(findings), loosened)

"""A candidate explanation as a type: an ordered set of terms, named ``a+b+base`` for display and JSON.

A diagnosis compares explanations of a recording: the plant as given (``nominal``), recalibrated
base parameters (``base``), one declared effect, an instrumentation finding (``instrument:...``),
or several of these found one after another (``valve_dynamics+internal_leakage``, in the order the
search added them). Results, reports and JSON key them by their canonical name; code that needs
the terms parses the name here, once, instead of splitting strings where it stands.
"""

from __future__ import annotations

from dataclasses import dataclass

from compliance.effects import EFFECTS

__all__ = ["BASE", "NOMINAL", "SEPARATOR", "CandidateSet"]

SEPARATOR = "+"
NOMINAL = "nominal"  # the plant as given: no term added
BASE = "base"  # recalibrating the base parameters (the plant's own, no new physics)


@dataclass(frozen=True)
class CandidateSet:
    """Terms of one candidate explanation, in the order they were found.

    Parameters
    ----------
    terms : tuple of str
        Effect names, ``base``, instrumentation findings, or (friction bench) law terms.
    """

    terms: tuple[str, ...]

    @classmethod
    def parse(cls, name: str | None) -> CandidateSet:
        """The set a canonical name stands for (``None`` and ``""`` give the empty set)."""
        return cls(tuple(t for t in (name or "").split(SEPARATOR) if t))

    @classmethod
    def of(cls, terms) -> CandidateSet:
        """The set of ``terms`` in their order."""
        return cls(tuple(terms))

    @property
    def name(self) -> str:
        """Canonical name: the terms joined by ``+`` (the key in results and JSON)."""
        return SEPARATOR.join(self.terms)

    def __str__(self) -> str:
        return self.name

    @property
    def effects(self) -> list[str]:
        """The declared effects among the terms (``base``, ``nominal``, instrumentation dropped), in order."""
        return [t for t in self.terms if t in EFFECTS]

    @property
    def first(self) -> str | None:
        """The first term found (the single-effect explanation the search started from)."""
        return self.terms[0] if self.terms else None

    def without(self, *drop: str) -> tuple[str, ...]:
        """The terms other than ``drop``, in their order."""
        return tuple(t for t in self.terms if t not in drop)

    @property
    def physics(self) -> frozenset[str]:
        """What the explanation claims of the plant: its terms without the base recalibration (order
        does not make other physics)."""
        return frozenset(self.without(BASE))

    def same_physics(self, other: CandidateSet) -> bool:
        """Both hold the same effects (``x`` and ``x+base`` are one explanation)."""
        return self.physics == other.physics

    def nested(self, other: CandidateSet) -> bool:
        """One's terms contain the other's (``base`` counting as one more term)."""
        a, b = frozenset(self.terms), frozenset(other.terms)
        return a <= b or b <= a

    def inside(self, other: CandidateSet) -> bool:
        """Its terms are a proper subset of ``other``'s (a simpler law inside a richer one)."""
        return frozenset(self.terms) < frozenset(other.terms)

    def plus(self, *terms: str) -> CandidateSet:
        """This set with ``terms`` added after its own."""
        return CandidateSet(self.terms + tuple(terms))

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

__all__ = ["BASE", "INSTRUMENT_PREFIX", "NOMINAL", "SEPARATOR", "CandidateSet", "is_instrument"]

SEPARATOR = "+"
NOMINAL = "nominal"  # the plant as given: no term added
BASE = "base"  # recalibrating the base parameters (the plant's own, no new physics)
INSTRUMENT_PREFIX = "instrument:"  # names of instrumentation findings (servo/instrument_candidates.py)


def is_instrument(name: str | None) -> bool:
    """True for the name of an instrumentation candidate (or of a term of a set, ``instrument:pressure_gain``)."""
    return bool(name) and name.startswith(INSTRUMENT_PREFIX)


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
    def plant_terms(self) -> frozenset[str]:
        """Its terms without instrumentation findings (a finding on top claims nothing of the plant)."""
        return frozenset(t for t in self.terms if not is_instrument(t))

    @property
    def physics(self) -> frozenset[str]:
        """What the explanation claims of the plant: its terms without the base recalibration and
        instrumentation findings (order does not make other physics)."""
        return self.plant_terms - {BASE}

    def same_physics(self, other: CandidateSet) -> bool:
        """Both hold the same effects (``x``, ``x+base`` and ``x`` with a finding on top are one explanation)."""
        return self.physics == other.physics

    def nested(self, other: CandidateSet) -> bool:
        """One's plant terms contain the other's (``base`` counting as one more term, a finding as none)."""
        a, b = self.plant_terms, other.plant_terms
        return a <= b or b <= a

    def inside(self, other: CandidateSet) -> bool:
        """Its terms are a proper subset of ``other``'s (a simpler law inside a richer one)."""
        return frozenset(self.terms) < frozenset(other.terms)

    def plus(self, *terms: str) -> CandidateSet:
        """This set with ``terms`` added after its own."""
        return CandidateSet(self.terms + tuple(terms))

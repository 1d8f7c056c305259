"""The declaration types of optional physics."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass


@dataclass(frozen=True)
class Param:
    """One parameter of an effect.

    Attributes
    ----------
    name : str
        Key inside ``[effects.NAME]``.
    unit : str
        SI unit (pint syntax) the value is stored in.
    meaning : str
        One line for reports and ``--help``.
    default : float
        Value used when the effect is switched on without this parameter.
    bounds : tuple of float
        Physically admissible range; the diagnosis fits within it.
    log_scale : bool
        Fit in log space (parameters spanning decades).
    """

    name: str
    unit: str
    meaning: str
    default: float
    bounds: tuple[float, float]
    log_scale: bool = False


@dataclass(frozen=True)
class Lumped:
    """A combination of an effect's parameters that a loop test pins down better than each one.

    Below a spool's or a transducer's own bandwidth a loop sees only their total lag; delay
    and lag then trade along a valley of the fit (Ljung 1999, ch. 13: identifiability from a
    finite-bandwidth experiment), while their sum stays sharp.

    Attributes
    ----------
    name : str
    unit : str
    meaning : str
    of : callable
        dict of the effect's SI parameter values -> the combination [unit].
    """

    name: str
    unit: str
    meaning: str
    of: Callable[[dict], float]


@dataclass(frozen=True)
class Effect:
    """An optional piece of physics.

    Attributes
    ----------
    name : str
    meaning : str
        One-line physics.
    params : tuple of Param
    states : tuple of str
        States it adds to the compiled core (names of the state vector entries).
    signature : str
        The trace it leaves in data (what a test engineer would look for).
    signals : tuple of str
        Canonical signals where it shows most (for ranking by located windows).
    lumped : Lumped or None
        The combination of its parameters a loop test identifies best, if they trade.
    """

    name: str
    meaning: str
    params: tuple[Param, ...]
    states: tuple[str, ...]
    signature: str
    signals: tuple[str, ...]
    lumped: Lumped | None = None

    def param(self, name: str) -> Param:
        """Return the declared parameter ``name``."""
        for p in self.params:
            if p.name == name:
                return p
        raise KeyError(name)

    def defaults(self) -> dict[str, float]:
        """Default parameter values, SI."""
        return {p.name: p.default for p in self.params}

"""The declaration types of optional physics."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from compliance.effects.param import Param


@dataclass(frozen=True)
class State:
    """A state an effect adds to the compiled core's state vector.

    Attributes
    ----------
    name : str
        Entry of ``compliance.model.vector_slots.STATE_NAMES``.
    slot : str
        Suffix of its index constant ``S_<slot>`` in the compiled code.
    index : int
        Its place in the state vector. Fixed, not counted: numba caches kernels with these
        integers frozen in, so an existing index never moves; a new state takes the next free one.
    """

    name: str
    slot: str
    index: int


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
    short : str
        Prefix of its parameter-vector entries (``<short>_on`` flag, ``<short>_<param slot>``) and
        of their index constants ``P_<SHORT>_ON``, ``P_<SHORT>_<SLOT>`` in the compiled code.
    params : tuple of Param
        Each with its ``slot`` (entry suffix).
    states : tuple of State
        States it adds to the compiled core (``plant_rhs`` integrates them); all of them are
        kept in the linear model while the effect is on.
    signature : str
        The trace it leaves in data (what a test engineer would look for).
    signals : tuple of str
        Canonical signals where it shows most (for ranking by located windows).
    lumped : Lumped or None
        The combination of its parameters a loop test identifies best, if they trade.
    loop_states : tuple of str
        States held by the sampled loop, outside the core's state vector (a measurement filter).
    input_delay : str or None
        Parameter that is a pure delay before the valve: the linear model puts a Pade
        approximant in front of the plant; plant B's tracking loop has no delay line for it.
    output_lag, output_delay : str or None
        Parameters that are a first-order lag and a pure delay of the position measurement:
        the linear model puts them between the plant and the controller.
    plant_b : bool
        Plant B's tracking loop (``simulate_axis``) can run with it switched on.
    explanation : str
        How the diagnosis says it, with ``{v}`` for its main fitted value.
    fit_grid : dict
        Parameter -> starting values of the diagnosis fit (their product is the coarse grid;
        parameters not named stay at their default).
    draw : dict
        Parameter -> (low, high, log) range the diagnosis benchmark draws concealed cases from.
    draw_signed : bool
        The benchmark flips the sign of the first parameter's draw half of the time.
    terms : dict
        Hook name (``catalogue.HOOKS``) -> the effect's compiled term for it. ``plant_rhs`` calls
        each hook once, as the chain of the declared terms in declared order; the chain calls a
        term only while its effect's flag is set (an effect that is off costs one compiled branch).
    """

    name: str
    meaning: str
    short: str
    params: tuple[Param, ...]
    states: tuple[State, ...]
    signature: str
    signals: tuple[str, ...]
    explanation: str
    fit_grid: dict[str, tuple[float, ...]]
    draw: dict[str, tuple[float, float, bool]]
    lumped: Lumped | None = None
    loop_states: tuple[str, ...] = ()
    input_delay: str | None = None
    output_lag: str | None = None
    output_delay: str | None = None
    plant_b: bool = True
    draw_signed: bool = False
    terms: dict[str, Callable] = field(default_factory=dict)

    def param(self, name: str) -> Param:
        """Return the declared parameter ``name``."""
        for p in self.params:
            if p.name == name:
                return p
        raise KeyError(name)

    def defaults(self) -> dict[str, float]:
        """Default parameter values, SI."""
        return {p.name: p.default for p in self.params}

    def state_names(self) -> tuple[str, ...]:
        """Names of the core states it adds."""
        return tuple(s.name for s in self.states)

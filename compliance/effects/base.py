"""The declaration types of optional physics."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import NamedTuple

from compliance.effects.param import Param

# typical magnitudes the linearisation scales its steps by (``compliance.linear.trim.state_scales``)
SCALES = ("stroke", "speed", "pressure", "temperature", "command")


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
    scale : str or callable
        Its typical magnitude, for the linearisation's steps: one of ``SCALES`` (the stroke
        [m], 0.1 m/s, the supply pressure [Pa], the supply temperature [K], the larger of the
        valve's saturation voltage and 1 V), or ``(P, scales) -> float`` given those by name.
    shadows : str or None
        The core state it copies while its effect is off (a second body moving with the first);
        ``plant_rhs`` keeps the copy, the linear and python-control models write it.
    """

    name: str
    slot: str
    index: int
    scale: str | Callable = "stroke"
    shadows: str | None = None


class Rest(NamedTuple):  # a tuple: built at every restart of a replay, where a frozen dataclass costs microseconds
    """A servo held at rest, as the effects' rest hooks read it (SI, absolute pressures).

    Attributes
    ----------
    position : float
        Position of the body carrying the sensor (2A1) [m].
    pressure_a, pressure_b : float
        Chamber pressures [Pa abs].
    supply_pressure : float
        Regulated supply pressure [Pa abs].
    supply_temperature : float
        [K].
    stroke : float
        [m].
    tandem : bool
        Two cylinders on one valve (plant A), else one.
    piston_forces : tuple of float
        Pneumatic force on each body, (2A1, 2A2) [N] (2A2's is 0 for a single cylinder).
    load : callable
        Closing force on the gate ring at a position [N] (with the effects' load terms).
    """

    position: float
    pressure_a: float
    pressure_b: float
    supply_pressure: float
    supply_temperature: float
    stroke: float
    tandem: bool
    piston_forces: tuple[float, float]
    load: Callable[[float], float]


@dataclass(frozen=True)
class Balance:
    """How the linear model's trim balances the closing load at rest (no friction), for an effect's hook.

    Attributes
    ----------
    position : float
        Position of the body carrying the sensor [m].
    tandem : bool
        Two cylinders on one valve.
    load : callable
        Closing force on the gate ring at a position [N].
    pressures : callable
        Closing force on the actuator [N] -> (p_A, p_B [Pa abs], largest closing load [N],
        largest opening load [N]) of the actuator at rest under it.
    piston_force : callable
        (p_A, p_B) -> pneumatic force on the body carrying the sensor [N].
    """

    position: float
    tandem: bool
    load: Callable[[float], float]
    pressures: Callable[[float], tuple]
    piston_force: Callable[[float, float], float]


class ReplayPoint(NamedTuple):
    """What a replay knows where it restarts a segment from a recording.

    Attributes
    ----------
    velocity : float
        Speed of the body carrying the sensor as the restart sets it [m/s].
    measured : dict
        Recorded canonical signal -> value at the restart (only the signals recorded).
    simulated : dict
        Output column (``compliance.simulation.rk4.OUTPUT_COLUMNS``) -> the previous segment's
        value at the restart (what is not measured is carried over).
    """

    velocity: float
    measured: dict[str, float]
    simulated: dict[str, float]


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
    slot : int
        Index of its on-flag ``P_<SHORT>_ON`` in the parameter vector; its parameters follow it in
        declared order. Fixed, not counted (numba caches kernels with the indices frozen in): a new
        effect takes the first index after every existing entry (``N_PARAMS``).
    requires : dict
        Configuration options it needs (option key -> value), checked when the parameter vector is built.
    frees : tuple of str
        Core states that stop copying another while it is on (a second body's friction bristle).
    command_state : str or None
        Its state through which the valve command reaches the ports (a spool): the linear model
        measures the flow column through it and does not count the effect's own rows as flow.

    The Python-level hooks of a structural effect (its own module writes them; ``compliance.effects.structure``
    calls each for every declared effect, on or off, in declared order; a hook reads its own flag):

    rest : callable or None
        ``rest(P, y, rest: Rest)``: its states in a servo at rest, in place (an effect that is off
        holds its states there too).
    hold : callable or None
        ``hold(P, y, rest: Rest)``: while on, the states that share the load in a servo held at rest
        (run again whenever the mechanical states are set).
    trim_balance : callable or None
        ``trim_balance(P, balance: Balance)``: while on, the load balance of the linear model's trim:
        None, or (closing force on the actuator [N], ``balance.pressures`` of it, {state index: value}).
    trim_null : callable or None
        ``trim_null(P, null)``: the valve command at the trim [V], given the core's.
    trim : callable or None
        ``trim(P, y, null)``: while on, its states at the trim with the valve at ``null`` [V], in place.
    replay_reset : callable or None
        ``replay_reset(P, y, point: ReplayPoint)``: its states where a replay restarts a segment
        from a recording, in place, after the core's states are set from it.
    reading_lag : callable or None
        ``reading_lag(P)``: while on, the lags [s] by which the recorded position trails the piston
        (a replay restarting from a recording reads the piston's position that much later).
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
    draw_signed: bool = False
    terms: dict[str, Callable] = field(default_factory=dict)
    slot: int = -1
    requires: dict[str, str] = field(default_factory=dict)
    frees: tuple[str, ...] = ()
    command_state: str | None = None
    rest: Callable | None = None
    hold: Callable | None = None
    trim_balance: Callable | None = None
    trim_null: Callable | None = None
    trim: Callable | None = None
    replay_reset: Callable | None = None
    reading_lag: Callable | None = None

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

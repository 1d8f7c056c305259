"""The one parameter schema: base parameters of a plant and parameters of declared effects alike."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Param:
    """One parameter: its key, SI unit, meaning, default, admissible range and where the core keeps it.

    Attributes
    ----------
    name : str
        Base parameter: dotted key ``section.name``; effect parameter: key inside ``[effects.NAME]``.
    unit : str
        SI unit (pint syntax); ``""`` dimensionless; ``"number"`` a bare SI number whose unit
        depends on another parameter (power-law coefficients).
    meaning : str
        One line for reports and ``--help``.
    default : float or None
        Value used when the file does not give one; None means required (base parameters only).
    bounds : tuple of float
        Physically admissible range (inclusive unless ``low_open``); an effect's fit stays within it.
    log_scale : bool
        Fit in log space (parameters spanning decades).
    low_open : bool
        The low bound is excluded (strictly positive quantities).
    pressure : bool
        An absolute pressure: the file must say ``abs`` or ``gauge``.
    fit_bounds : tuple of float or None
        Range the diagnosis may refit a base parameter in (None: never refitted).
    slot : str or None
        Name of its entry in the compiled core's parameter vector (``compliance.model.vector_slots``);
        an effect parameter's entry is ``<effect short>_<slot>``. None: not copied into the vector.
    aliases : tuple of str
        Other names recordings with answers (ANSWERS.json of the practice emulator) use for it.
    """

    name: str
    unit: str
    meaning: str
    default: float | None
    bounds: tuple[float, float] = (0.0, float("inf"))
    log_scale: bool = False
    low_open: bool = False
    pressure: bool = False
    fit_bounds: tuple[float, float] | None = None
    slot: str | None = None
    aliases: tuple[str, ...] = ()

"""Parameter paths a sweep may move: any base parameter (``controller.kp``) or declared effect
parameter (``effects.internal_leakage.conductance``), with its SI unit and admissible bounds.

The base parameter table (``compliance.model.parameters``) and the effect declarations
(``compliance.effects``) are the single source of what exists; this module only reads them.
"""

from __future__ import annotations

from dataclasses import dataclass

from compliance.effects import EFFECTS
from compliance.errors import InputError, did_you_mean
from compliance.model.parameters import BASE_BY_KEY

__all__ = ["ParamPath", "apply_values", "describe"]


@dataclass(frozen=True)
class ParamPath:
    """A movable parameter: its dotted path, SI unit, meaning and admissible [low, high]."""

    path: str
    unit: str
    meaning: str
    low: float
    high: float
    pressure: bool = False  # an absolute pressure: values must say abs or gauge
    effect: str | None = None  # effect name for ``effects.NAME.PARAM``

    @property
    def name(self) -> str:
        """The parameter's key inside its section (base key or effect parameter)."""
        return self.path.split(".", 2)[2] if self.effect else self.path


def describe(path: str, where: str) -> ParamPath:
    """The :class:`ParamPath` of ``path``; :class:`InputError` naming ``where`` when it is unknown."""
    if path.startswith("effects."):
        parts = path.split(".")
        if len(parts) != 3 or parts[1] not in EFFECTS:
            name = parts[1] if len(parts) > 1 else ""
            raise InputError(f"{where}: '{path}' is not a declared parameter path (effects.NAME.PARAM with NAME one of "
                             f"{', '.join(sorted(EFFECTS))}){did_you_mean(name, EFFECTS)}")
        eff = EFFECTS[parts[1]]
        try:
            prm = eff.param(parts[2])
        except KeyError:
            raise InputError(f"{where}: effect {eff.name} has no parameter '{parts[2]}' "
                             f"(it has {', '.join(p.name for p in eff.params)}){did_you_mean(parts[2], [p.name for p in eff.params])}") from None
        return ParamPath(path, prm.unit, prm.meaning, prm.bounds[0], prm.bounds[1], effect=eff.name)
    spec = BASE_BY_KEY.get(path)
    if spec is None:
        raise InputError(f"{where}: '{path}' is not a known parameter path{did_you_mean(path, BASE_BY_KEY)} "
                         "(docs/physics.md lists the parameters; effect parameters are effects.NAME.PARAM)")
    if spec.unit == "number":
        raise InputError(f"{where}: '{path}' is a bare power-law coefficient; sweep a parameter with a unit")
    return ParamPath(path, spec.unit, spec.meaning, spec.bounds[0], spec.bounds[1], pressure=spec.pressure)


def apply_values(cfg, paths: dict, values: dict):
    """``cfg`` with the SI ``values`` (path -> float) set; effects named are switched on.

    Parameters
    ----------
    cfg : PlantConfig
    paths : dict
        path -> :class:`ParamPath`.
    values : dict
        path -> SI float.
    """
    params, effects = {}, {}
    for path, v in values.items():
        pp = paths[path]
        if pp.effect:
            effects.setdefault(pp.effect, dict(cfg.effects.get(pp.effect, {})))[pp.name] = float(v)
        else:
            params[path] = float(v)
    if not params and not effects:
        return cfg
    return cfg.replace(params=params, effects=effects)

"""What seed 000 leaves unstated, as data: parameter path, plausible range, reason.

The calibration (``calibration.py``) may move only what is listed here, only inside the
range, and says why the range is plausible. Everything the paper states (geometry, mass,
supply, dead zone, lc, the PID gains) stays as printed. Test conditions the lost figures
leave open are discrete choices. Paths are dotted base keys (``friction.coulomb_force``) or
``effects.NAME.PARAM`` for a declared effect (only when the configuration switches it on).
"""

from __future__ import annotations

from dataclasses import dataclass

from compliance.diagnosis.servo.candidates import FitParam
from compliance.effects import EFFECTS
from compliance.model.config import PlantConfig
from compliance.model.parameters import BASE_BY_KEY

# breakaway over Coulomb friction of lip seals (the static force's plausible range, as a ratio)
BREAKAWAY_RATIO = (1.0, 1.6)

CALIBRATED_SOURCE = "calibrated to seed 000 figures 9-12 and section 5.2 (govcheck reproduce plant-a --calibrate)"


@dataclass(frozen=True)
class Unstated:
    """A parameter the paper does not give, with the range a real plant of its kind could have.

    Attributes
    ----------
    path : str
        ``section.name`` or ``effects.NAME.PARAM``.
    low, high : float
        Plausible range [SI].
    log : bool
        Search in log space (ranges spanning a decade or more).
    reason : str
        Why the paper leaves it open and why the range is plausible.
    """

    path: str
    low: float
    high: float
    log: bool
    reason: str

    @property
    def unit(self) -> str:
        """SI unit of the value."""
        if self.path.startswith("effects."):
            _, eff, name = self.path.split(".")
            return EFFECTS[eff].param(name).unit
        return BASE_BY_KEY[self.path].unit


@dataclass(frozen=True)
class Condition:
    """A test condition the paper's lost figures leave open: one of a few choices."""

    name: str
    choices: tuple[str, ...]
    reason: str


UNSTATED: tuple[Unstated, ...] = (
    Unstated("valve.saturation_voltage", 2.0, 10.0, False,
             "fig. 2a (relative opening vs command) is lost; proportional valves reach full opening between "
             "20 % and 100 % of the +/-10 V command"),
    Unstated("friction.coulomb_force", 100.0, 900.0, True,
             "fig. 3 (friction maps) is lost; 125 mm piston + 32 mm rod seals: 1-6 % of the 16 kN theoretical "
             "force at 7 bar"),
    Unstated("friction.static_force", 100.0, 1400.0, True,
             "fig. 3 is lost; breakaway 1.0-1.6 x Coulomb for lip seals (held within that ratio of the Coulomb force)"),
    Unstated("friction.stribeck_velocity", 0.001, 0.03, True,
             "fig. 3 is lost; pneumatic seal maps fall from static to Coulomb within 1-30 mm/s"),
    Unstated("friction.viscous_coefficient", 100.0, 3000.0, True,
             "fig. 3 is lost; viscous slope of pneumatic seals 0.1-3 kN*s/m per cylinder"),
    Unstated("controller.filter_cutoff", 10.0, 200.0, True,
             "section 5: 'first-class low-pass filters' on the measured position, cut-off not given"),
    Unstated("flow_control.opening_conductance", 1.5e-9, 1.5e-8, True,
             "2V3 setting not given, only that it gave t_a = 5 s at 5.7 kN (section 5.2)"),
    Unstated("flow_control.closing_conductance", 1.5e-9, 1.5e-8, True,
             "2V2 setting not given, only that it gave t_f = 5 s at 5.7 kN (section 5.2)"),
)

# the effect the paper points at for what the parameters above cannot reach (valve flow near null)
NULL_FLOW_EFFECT = "valve_null_flow"
EFFECT_UNSTATED: tuple[Unstated, ...] = (
    Unstated(f"effects.{NULL_FLOW_EFFECT}.null_opening", 0.001, 0.05, True,
             "section 3: the valve has 'a region where there is no flow' only nominally; a real spool leaks "
             "across its lands, 0.1-5 % of the rated opening"),
    Unstated(f"effects.{NULL_FLOW_EFFECT}.null_width", 0.05, 1.5, True,
             "pressure gain at null: servo valves swing a port from exhaust to supply within 0.5-15 % of the "
             "rated command (0.05-1.5 V)"),
)

CONDITIONS: tuple[Condition, ...] = (
    Condition("fig9_sequence", ("alternating", "staircase"),
              "fig. 9 is lost: its three 2 % steps may go up/down/up or up/up/up"),
    Condition("full_stroke_start", ("balanced", "end_stop"),
              "section 5.2 does not say how the full strokes start: at rest with balanced pressures, or from "
              "the end stop the previous stroke drove the servo to (one side at supply, the other exhausted)"),
)


def unstated_for(cfg: PlantConfig) -> tuple[Unstated, ...]:
    """The unstated parameters that apply to ``cfg`` (effect ones only when the effect is on)."""
    extra = tuple(u for u in EFFECT_UNSTATED if u.path.split(".")[1] in cfg.effects)
    return UNSTATED + extra


def fit_param(u: Unstated, cfg: PlantConfig) -> FitParam:
    """The unit-cube search coordinate of an unstated parameter (``FitParam`` of the diagnosis)."""
    return FitParam(u.path, "effect" if u.path.startswith("effects.") else "base", u.unit, u.low, u.high, u.log,
                    value_of(cfg, u.path))


def value_of(cfg: PlantConfig, path: str) -> float:
    """Current SI value of ``path`` in ``cfg``."""
    if path.startswith("effects."):
        _, eff, name = path.split(".")
        return float(cfg.effects[eff][name])
    return float(cfg.p(path))


def apply_values(cfg: PlantConfig, values: dict[str, float], source: str = CALIBRATED_SOURCE) -> PlantConfig:
    """``cfg`` with ``values`` (path -> SI) set, every changed base value's source = ``source``.

    The static friction is held within ``BREAKAWAY_RATIO`` times the Coulomb force: below it is not
    physical (the loader refuses it), above it is outside what the range's reason allows.
    """
    base: dict[str, float] = {}
    effects: dict[str, dict[str, float]] = {}
    for path, v in values.items():
        if path.startswith("effects."):
            _, eff, name = path.split(".")
            effects.setdefault(eff, {})[name] = float(v)
        else:
            base[path] = float(v)
    if "friction.coulomb_force" in base or "friction.static_force" in base:
        fc = base.get("friction.coulomb_force", cfg.p("friction.coulomb_force"))
        fs = base.get("friction.static_force", cfg.p("friction.static_force"))
        lo, hi = BREAKAWAY_RATIO
        base["friction.static_force"] = min(max(fs, lo * fc), hi * fc)
    return cfg.replace(params=base or None, effects=effects or None, sources={k: source for k in base})

"""What seed 000 leaves unstated, as data: parameter path, plausible range, reason.

The calibration (``calibration.py``) may move only what is listed here, only inside the
range, and says why the range is plausible. Everything the paper states (geometry, mass,
supply, dead zone, lc, the PID gains) stays as printed. Test conditions the lost figures
leave open are discrete choices. Each entry is a ``compliance.model.parameters.ParamHandle`` narrowed to
its plausible range with the reason (:func:`unstated`): a dotted base key (``friction.coulomb_force``) or
``effects.NAME.PARAM`` for a declared effect (only when the configuration switches it on).
"""

from __future__ import annotations

from dataclasses import dataclass

from compliance.model.config import PlantConfig
from compliance.model.parameters import ParamHandle, param_handle

# breakaway over Coulomb friction of lip seals (the static force's plausible range, as a ratio)
BREAKAWAY_RATIO = (1.0, 1.6)

CALIBRATED_SOURCE = "calibrated to seed 000 figures 9-12 and section 5.2 (govcheck reproduce plant-a --calibrate)"


def unstated(path: str, low: float, high: float, log: bool, reason: str) -> ParamHandle:
    """A parameter the paper does not give, with the range [SI] a real plant of its kind could have.

    ``log``: searched in log space (ranges spanning a decade or more); ``reason``: why the paper leaves it
    open and why the range is plausible.
    """
    return param_handle(path, "calibration table").within(low, high, log, reason)


@dataclass(frozen=True)
class Condition:
    """A test condition the paper's lost figures leave open: one of a few choices."""

    name: str
    choices: tuple[str, ...]
    reason: str


UNSTATED: tuple[ParamHandle, ...] = (
    unstated("valve.saturation_voltage", 2.0, 10.0, False,
             "fig. 2a (relative opening vs command) is lost; proportional valves reach full opening between "
             "20 % and 100 % of the +/-10 V command"),
    unstated("friction.coulomb_force", 100.0, 900.0, True,
             "fig. 3 (friction maps) is lost; 125 mm piston + 32 mm rod seals: 1-6 % of the 16 kN theoretical "
             "force at 7 bar"),
    unstated("friction.static_force", 100.0, 1400.0, True,
             "fig. 3 is lost; breakaway 1.0-1.6 x Coulomb for lip seals (held within that ratio of the Coulomb force)"),
    unstated("friction.stribeck_velocity", 0.001, 0.03, True,
             "fig. 3 is lost; pneumatic seal maps fall from static to Coulomb within 1-30 mm/s"),
    unstated("friction.viscous_coefficient", 100.0, 3000.0, True,
             "fig. 3 is lost; viscous slope of pneumatic seals 0.1-3 kN*s/m per cylinder"),
    unstated("controller.filter_cutoff", 10.0, 200.0, True,
             "section 5: 'first-class low-pass filters' on the measured position, cut-off not given"),
    unstated("flow_control.opening_conductance", 1.5e-9, 1.5e-8, True,
             "2V3 setting not given, only that it gave t_a = 5 s at 5.7 kN (section 5.2)"),
    unstated("flow_control.closing_conductance", 1.5e-9, 1.5e-8, True,
             "2V2 setting not given, only that it gave t_f = 5 s at 5.7 kN (section 5.2)"),
)

# the effect the paper points at for what the parameters above cannot reach (valve flow near null)
NULL_FLOW_EFFECT = "valve_null_flow"
EFFECT_UNSTATED: tuple[ParamHandle, ...] = (
    unstated(f"effects.{NULL_FLOW_EFFECT}.null_opening", 0.001, 0.05, True,
             "section 3: the valve has 'a region where there is no flow' only nominally; a real spool leaks "
             "across its lands, 0.1-5 % of the rated opening"),
    unstated(f"effects.{NULL_FLOW_EFFECT}.null_width", 0.05, 1.5, True,
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


def unstated_for(cfg: PlantConfig) -> tuple[ParamHandle, ...]:
    """The unstated parameters that apply to ``cfg`` (effect ones only when the effect is on)."""
    extra = tuple(u for u in EFFECT_UNSTATED if u.effect in cfg.effects)
    return UNSTATED + extra


def held_breakaway(cfg: PlantConfig, handles, values) -> tuple[list[ParamHandle], list[float]]:
    """``handles`` and ``values`` with the static friction held within ``BREAKAWAY_RATIO`` times the Coulomb force.

    Below it is not physical (the loader refuses it), above it is outside what the range's reason allows;
    the static force joins the values when only the Coulomb force moves.
    """
    handles, values = list(handles), [float(v) for v in values]
    paths = [h.path for h in handles]
    if "friction.coulomb_force" not in paths and "friction.static_force" not in paths:
        return handles, values
    given = dict(zip(paths, values))
    fc = given.get("friction.coulomb_force", cfg.p("friction.coulomb_force"))
    fs = given.get("friction.static_force", cfg.p("friction.static_force"))
    lo, hi = BREAKAWAY_RATIO
    held = min(max(fs, lo * fc), hi * fc)
    if "friction.static_force" in paths:
        values[paths.index("friction.static_force")] = held
    else:
        handles.append(param_handle("friction.static_force", "calibration"))
        values.append(held)
    return handles, values

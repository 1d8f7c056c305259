"""Bench characterisation: valve flow law from a charged volume, friction map from constant-speed runs.

- ``charging``: mass flow from the pressure of a fixed volume, flow-law ranking, synthetic data.
- ``flow_law``: vectorised ISO 6358 / Sanville / Bobrow / power laws and their fits.
- ``friction_runs``: friction from force and pressure per run (recorded or synthetic).
- ``friction_map``: speed bins and Stribeck map fits over the runs.
- ``derivative``: Savitzky-Golay value and derivative on the actual sample times.

See docs/characterisation.md.
"""

from compliance.characterise.charging import ValveCharacterisation, characterise_valve, mass_flow_from_pressure, synthetic_charging
from compliance.characterise.derivative import smoothed_derivative
from compliance.characterise.flow_law import (
    LAWS,
    FlowFit,
    bobrow_mass_flow,
    fit_flow_law,
    iso6358_mass_flow,
    power_law_mass_flow,
    rank_flow_laws,
    sanville_mass_flow,
)
from compliance.characterise.friction_map import (
    FrictionCharacterisation,
    FrictionFit,
    FrictionRun,
    bin_friction,
    characterise_friction,
    fit_friction_map,
    friction_from_force,
    piston_area,
    prepare_run,
    stribeck_friction,
    synthetic_friction_run,
)

__all__ = [
    "LAWS",
    "FlowFit",
    "FrictionCharacterisation",
    "FrictionFit",
    "FrictionRun",
    "ValveCharacterisation",
    "bin_friction",
    "bobrow_mass_flow",
    "characterise_friction",
    "characterise_valve",
    "fit_flow_law",
    "fit_friction_map",
    "friction_from_force",
    "iso6358_mass_flow",
    "mass_flow_from_pressure",
    "piston_area",
    "power_law_mass_flow",
    "prepare_run",
    "rank_flow_laws",
    "sanville_mass_flow",
    "smoothed_derivative",
    "stribeck_friction",
    "synthetic_charging",
    "synthetic_friction_run",
]

"""A fitted flow law with a non-positive conductance or area is never 'best' (issue 16)."""

from __future__ import annotations

import numpy as np
import pytest

from compliance.characterise.flow_law import implausibility, iso6358_mass_flow, rank_flow_laws
from compliance.errors import InputError

C = 2.33e-8  # m^3/(s*Pa): plant A's valve, 2.33 dm^3/(s*bar)


def _charging():
    p_up = np.full(200, 8.0e5)
    p_down = np.linspace(1.2e5, 7.5e5, 200)
    t_up = np.full(200, 293.15)
    return p_up, p_down, t_up, iso6358_mass_flow(p_up, p_down, t_up, C, 0.528)


def test_true_charging_recovers_a_positive_conductance_first():
    p_up, p_down, t_up, q = _charging()
    fits = rank_flow_laws(p_up, p_down, t_up, q)
    assert fits[0].implausible is None
    iso = next(f for f in fits if f.law == "iso6358")
    assert iso.params["conductance"] == pytest.approx(C, rel=1e-6)


def test_flow_against_the_pressure_drop_is_refused():
    p_up, p_down, t_up, q = _charging()
    with pytest.raises(InputError, match="is this a charging test"):
        rank_flow_laws(p_up, p_down, t_up, -q)


def test_implausible_fits_rank_last():
    assert implausibility("iso6358", {"conductance": -1e-8, "critical_ratio": 0.5}).startswith("conductance = -1e-08")
    assert implausibility("power-0.25", {"cf1": 1.0, "cf2": -1.0}).startswith("cf2")
    assert implausibility("sanville", {"area": 1e-6}) is None

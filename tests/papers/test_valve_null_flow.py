"""The valve's null flow (effect valve_null_flow) moves the steady error the way its physics says."""

from __future__ import annotations

import pytest
from scipy.optimize import brentq

from compliance.metrics import find_steps, step_response
from compliance.model.config import load_plant
from compliance.model.pid_controller import stall_error
from compliance.physics.valve_flow import iso6358_mass_flow
from compliance.effects.valve_null_flow import land_leak_openings
from compliance.physics.valve_opening import valve_openings
from compliance.simulation import Scenario
from compliance.plants import simulate
from compliance.simulation.profiles import steps


def _steady_errors(cfg):
    """Steady errors of a 5 % step up then down at mid-stroke, no load, K_D = 20 [m]."""
    df = simulate(cfg, Scenario(duration=6.5, initial_position=0.08, reference=steps("5%@0.5s,-5%@3.5s", 0.08, 0.16)))
    t = df.time.to_numpy()
    return [step_response(t, df.position_true.to_numpy(), ev).steady_state_error
            for ev in find_steps(t, df.reference.to_numpy())]


def _with_null_flow(opening, width=0.3):
    return load_plant("plant-a").replace(effects={"valve_null_flow": {"null_opening": opening, "null_width": width}})


def test_zero_flow_at_null_leaves_the_stall_band():
    """Ideal dead zone: the compensated valve shuts once |e| < zmd*lc/((zmd + lc)*K_P) (0.86 mm up, 0.90 mm down)
    and nothing moves the servo after that; 0.1 mm allows the coast after the valve shuts."""
    cfg = load_plant("plant-a")
    up, down = _steady_errors(cfg)
    assert up == pytest.approx(stall_error(cfg, "opening"), abs=0.1e-3)
    assert down == pytest.approx(stall_error(cfg, "closing"), abs=0.1e-3)


def test_finite_null_flow_shrinks_the_steady_error_monotonically():
    """Leaking lands keep a pressure gain inside the dead zone: the loop stays stiff and pushes on. More leak,
    smaller error; 0.5 % leak with 0.3 V width brings both errors below a quarter of the stall band."""
    band = stall_error(load_plant("plant-a"), "opening")
    errs = [max(_steady_errors(_with_null_flow(a))) for a in (0.002, 0.005, 0.01)]
    assert errs[0] > errs[1] > errs[2]
    assert errs[1] < 0.25 * band


def _port_pressure(u, opening, width, ps=8.0e5, patm=1.013e5, c=2.33e-8):
    """Steady pressure of a blocked port A: inflow P->A equals outflow A->T (ISO 6358, seed 000 eq. 1)."""
    dz_pa, dz_at, _, _ = valve_openings(u, 0.61, 0.69, 1.0, 1.0, 4.0)
    l_pa, l_at, _, _ = land_leak_openings(u, opening, width, 0.61, 0.69)

    def net(p):
        q_in = iso6358_mass_flow(1.0, c * (dz_pa + l_pa), ps, p, 293.15, 0.528, 1.204, 293.15)
        q_out = iso6358_mass_flow(1.0, c * (dz_at + l_at), p, patm, 293.15, 0.528, 1.204, 293.15)
        return q_in - q_out

    lo, hi = patm * 1.0001, ps * 0.9999
    if net(hi) >= 0.0:  # the exhaust land is covered: the port fills to supply
        return ps
    if net(lo) <= 0.0:
        return patm
    return brentq(net, lo, hi)


def test_null_flow_gives_a_pressure_gain_at_null():
    """With leaking lands a blocked port settles between exhaust and supply and follows the command inside the
    dead zone (finite pressure gain); with the ideal valve every path is shut there (no flow, no gain)."""
    assert valve_openings(0.3, 0.61, 0.69, 1.0, 1.0, 4.0) == (0.0, 0.0, 0.0, 0.0)
    p0 = _port_pressure(0.0, 0.005, 0.3)
    assert 1.013e5 < p0 < 8.0e5
    gain = (_port_pressure(0.05, 0.005, 0.3) - _port_pressure(-0.05, 0.005, 0.3)) / 0.1
    assert gain > 1e5  # Pa/V: over 1 bar per volt near null
    # the swing is set by the width: a covered land stops leaking at |u| = width
    assert _port_pressure(0.3, 0.005, 0.3) == 8.0e5 and _port_pressure(-0.3, 0.005, 0.3) < 1.1e5


def test_an_uncovering_land_keeps_opening_up_to_its_metering_edge():
    """Underlap-like leak (w = 0.1 V, inside the 0.61/0.69 V dead zone): the land the command covers is shut from
    |u| = w, the one it uncovers keeps opening with the travel (slope a0/w) until its edge, where the nominal
    opening takes over: the total opening of the path is continuous and strictly rising through the dead zone
    and its edge, so the loop keeps a flow gain everywhere (no flat band between w and the dead zone)."""
    a0, w = 0.004, 0.1
    for sign, dz in ((+1.0, 0.61), (-1.0, 0.69)):
        def path(u):  # P->A for u > 0, A->T for u < 0: the uncovering path
            nominal = valve_openings(sign * u, 0.61, 0.69, 1.0, 1.0, 4.0)
            leak = land_leak_openings(sign * u, a0, w, 0.61, 0.69)
            k = 0 if sign > 0 else 1
            return nominal[k] + leak[k], leak[2 if sign > 0 else 3]

        us = [0.0, 0.05, 0.2, 0.4, dz - 1e-6, dz + 1e-6, dz + 0.2]
        opened = [path(u)[0] for u in us]
        assert all(b > a for a, b in zip(opened, opened[1:]))
        assert opened[1] - opened[0] == pytest.approx(a0 * 0.05 / w, rel=1e-9)  # slope a0/w near null
        assert opened[3] - opened[2] == pytest.approx(a0 * 0.2 / w, rel=1e-9)  # still a0/w beyond w
        assert opened[5] - opened[4] == pytest.approx(0.0, abs=1e-5)  # continuous at the metering edge
        assert path(0.2)[1] == 0.0  # the covered land is shut beyond w
    # the equivalent underlap wider than the dead zone (a critically lapped valve, plant B): leak capped at 2 a0
    assert land_leak_openings(1.0, a0, 0.3, 0.0, 0.0)[0] == pytest.approx(2 * a0)

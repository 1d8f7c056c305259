"""Seed 000 fig. 8: the dead-zone compensation shortens settling (steady errors set by the dead-zone physics)."""

from __future__ import annotations

import pytest

from compliance.model.config import load_plant
from compliance.model.pid_controller import stall_error
from compliance.papers.plant_a_fig8 import fig8

CREEP = 0.42e-3  # F_S / sigma0 per cylinder: pre-sliding after the valve shuts (bound)


@pytest.fixture(scope="module")
def rows():
    return fig8(load_plant("plant-a"))


def test_uncompensated_servo_stalls_a_dead_zone_short(rows):
    """Without compensation the valve shuts once K_P*|e| < zmd (up) or zme (down): e = dz/K_P = 2.18 / 2.46 mm."""
    cfg = load_plant("plant-a")
    kp = cfg.p("controller.kp")
    for r in (r for r in rows if r.variant == "without compensation"):
        dz = cfg.p("valve.dead_zone_positive" if r.direction == "up" else "valve.dead_zone_negative")
        assert dz / kp - 0.1e-3 <= r.steady_error <= dz / kp + CREEP
        assert r.setpoint_time is None  # 2.2 mm > 1 % of stroke: never within the positioning tolerance


def test_compensation_shortens_settling_to_the_set_point(rows):
    cfg = load_plant("plant-a")
    band = stall_error(cfg, "opening")
    for r in (r for r in rows if r.variant == "with compensation"):
        assert r.steady_error <= max(band, stall_error(cfg, "closing")) + CREEP
        assert r.setpoint_time is not None and r.setpoint_time < 1.0

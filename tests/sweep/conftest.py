"""Shared fixtures of the sweep tests: a two-requirement file (tests/data/sweep-small-tc.toml) and sweep files on it."""

from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
SMALL_TC = HERE.parent / "data" / "sweep-small-tc.toml"


def sweep_text(method="grid", extra="", adjust=None) -> str:
    """A sweep of plant A's proportional and derivative gains against sweep-small-tc.toml."""
    adjust = adjust if adjust is not None else """
[adjust."controller.kp"]
range = ["200 V/m", "500 V/m"]
steps = 4
[adjust."controller.kd"]
values = ["10 V*s/m", "20 V*s/m"]
"""
    return f"""
schema = "govcheck-sweep/1"
name = "small"
base = "plant-a"
requirements = "{SMALL_TC}"
[search]
method = "{method}"
samples = 6
seed = 3
iterations = 3
{adjust}
[uncertain."friction.static_force"]
distribution = "uniform"
half_width = "20 %"
[uncertain."valve.sonic_conductance"]
distribution = "normal"
std = "5 %"
[yield]
units = 12
seed = 5
{extra}
"""


@pytest.fixture
def write_sweep(tmp_path):
    def _write(text: str, name="s.toml") -> Path:
        p = tmp_path / name
        p.write_text(text)
        return p
    return _write

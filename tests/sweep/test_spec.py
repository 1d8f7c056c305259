"""Sweep files: validated at the edge; every bad file is one message naming the field, exit 2."""

import pytest

from compliance.cli import main
from compliance.sweep.candidates.spec import load_sweep

from tests.sweep.conftest import sweep_text


def test_good_file_is_si(write_sweep):
    s = load_sweep(write_sweep(sweep_text()))
    kp, kd = s.adjust
    assert (kp.param.path, kp.low, kp.high, kp.steps) == ("controller.kp", 200.0, 500.0, 4)
    assert kd.values == (10.0, 20.0)
    fs = s.uncertain[0]
    assert (fs.distribution, fs.spread, fs.relative) == ("uniform", pytest.approx(0.2), True)


@pytest.mark.parametrize("adjust, needle", [
    ('[adjust."controller.kpp"]\nrange = ["200 V/m", "500 V/m"]', "controller.kpp"),      # unknown path
    ('[adjust."controller.kp"]\nrange = ["200 mm", "500 mm"]', 'adjust."controller.kp".range[0]'),  # wrong unit
    ('[adjust."controller.kp"]\nrange = ["500 V/m", "200 V/m"]', "empty range"),
    ('[adjust."controller.kp"]\nrange = ["200 V/m", "200 V/m"]', "empty range"),
    ('[adjust."air.supply_pressure"]\nrange = ["6 bar", "8 bar"]', "abs"),  # pressures say abs/gauge
    ('[adjust."effects.sensor_lag.nope"]\nvalues = ["1 ms"]', "sensor_lag has no parameter 'nope'"),
    ('[adjust."controller.kp"]\nrange = ["200 V/m", "500 V/m"]\nstep = 3', "step"),  # unknown field
])
def test_bad_adjust_is_exit_2_naming_the_field(write_sweep, capsys, adjust, needle):
    code = main(["sweep", str(write_sweep(sweep_text(adjust=adjust)))])
    err = capsys.readouterr().err
    assert code == 2
    assert needle in err and "Traceback" not in err
    assert err.count("\n") == 1  # one message


def test_negative_tolerance_is_exit_2(write_sweep, capsys):
    text = sweep_text().replace('half_width = "20 %"', 'half_width = "-20 %"')
    assert main(["sweep", str(write_sweep(text))]) == 2
    err = capsys.readouterr().err
    assert 'uncertain."friction.static_force".half_width' in err and "negative tolerance" in err


def test_missing_spread_and_bad_method_are_exit_2(write_sweep, capsys):
    assert main(["sweep", str(write_sweep(sweep_text().replace('std = "5 %"', "")))]) == 2
    assert "needs std" in capsys.readouterr().err
    assert main(["sweep", str(write_sweep(sweep_text(method="random")))]) == 2
    assert "search.method" in capsys.readouterr().err


def test_bad_scheduler_is_exit_2(write_sweep, capsys):
    assert main(["sweep", str(write_sweep(sweep_text())), "--scheduler", "local:0"]) == 2
    assert "local:N" in capsys.readouterr().err


def test_check_remedies_with_bad_sweep_file_is_exit_2_before_simulating(write_sweep, capsys):
    from tests.sweep.conftest import SMALL_TC

    bad = write_sweep(sweep_text(adjust='[adjust."controller.kp"]\nrange = ["1 s", "2 s"]'))
    assert main(["check", "plant-a", "-r", str(SMALL_TC), "--remedies", str(bad)]) == 2
    captured = capsys.readouterr()
    assert 'adjust."controller.kp".range[0]' in captured.err and captured.out == ""

"""linear_model: govcheck's own linear model as python-control objects, signals named with their units."""

from __future__ import annotations

import numpy as np
import pytest

control = pytest.importorskip("control")

from compliance.errors import InputError  # noqa: E402
from compliance.linear.analysis import analyse  # noqa: E402
from compliance.linear.linear_model import linear_model  # noqa: E402
from compliance.linear.nlsys import to_statespace  # noqa: E402
from compliance.model.config import load_plant  # noqa: E402


@pytest.fixture(scope="module")
def cfg():
    return load_plant("plant-a")


@pytest.mark.parametrize("mode", ["mean", "opening", "closing"])
def test_it_is_govcheck_linear_model_for_each_valve_slope(cfg, mode):
    m = linear_model(cfg, 0.136, 11400.0, mode=mode)
    a = analyse(cfg, 0.136, 11400.0, gain=mode)
    np.testing.assert_allclose(np.sort_complex(m.poles()), np.sort_complex(a.closed_loop.poles()), rtol=1e-12)
    assert m.figures["time_constant"] == a.figures["time_constant"] and m.mode == mode


def test_every_signal_carries_its_unit_and_the_removed_pole_is_stated(cfg):
    m = linear_model("plant-a", "136 mm", "11.4 kN")
    assert m.plant.input_labels == ["u_d_V"] and m.plant.output_labels == ["position_m"]
    assert m.plant.state_labels == ["position_m", "velocity_m_s", "pressure_a_Pa", "pressure_b_Pa"]
    assert m.closed_loop.input_labels == ["reference_m"] and m.closed_loop.output_labels == ["position_m"]
    assert m.loop.input_labels == ["u_d_V"] and m.loop.output_labels == ["u_d_return_V"]
    assert m.removed[0]["modes"] == 1 and m.removed[0]["poles"] == [0j]
    # the full plant keeps two poles at 0 (piston integrator, common pressure level), the minimal one the integrator
    assert int(np.sum(np.abs(m.plant.poles()) < 1e-9)) == 2 and int(np.sum(np.abs(m.plant_minimal.poles()) < 1e-9)) == 1
    ss = to_statespace(cfg, 0.136, 11400.0)
    assert ss.input_labels == ["u_d_V"] and ss.output_labels == ["position_m"] and ss.state_labels[0] == "position_m"


def test_step_info_dcgain_bandwidth_work_on_the_loop_object(cfg):
    m = linear_model(cfg, 0.136, 11400.0)
    assert control.dcgain(m.closed_loop) == pytest.approx(1.0, abs=1e-9)
    assert control.bandwidth(m.closed_loop) / (2 * np.pi) == pytest.approx(m.figures["bandwidth_hz"], rel=1e-9)
    info = control.step_info(m.closed_loop)
    assert all(np.isfinite(v) for v in info.values())
    gm, pm, _, _ = control.margin(m.loop)
    assert control.mag2db(gm) == pytest.approx(m.figures["gain_margin_db_continuous"], abs=0.01)
    assert pm == pytest.approx(m.figures["phase_margin_deg_continuous"], abs=0.01)


def test_unknown_mode_and_bad_point_are_input_errors(cfg):
    with pytest.raises(InputError, match="mode 'average'"):
        linear_model(cfg, 0.136, mode="average")
    with pytest.raises(InputError):
        linear_model(cfg, "136 kg")

"""A plant kind is a room: each kind answers the interface the rest of the package asks (compliance.plants)."""

from __future__ import annotations

import numpy as np
import pytest

from compliance.errors import InputError
from compliance.model.config import load_plant
from compliance.model.parameters import OPTIONS
from compliance.model.pid_controller import stall_error
from compliance.plants import KINDS, PlantKind, kind_of, simulate
from compliance.plants.pid_servo import PID_SERVO
from compliance.plants.state_feedback_drive import STATE_FEEDBACK_DRIVE
from compliance.simulation import Scenario
from compliance.simulation.profiles import steps


@pytest.fixture(scope="module")
def plants():
    return load_plant("plant-a"), load_plant("plant-b")


def test_every_controller_type_of_the_schema_is_a_kind(plants):
    assert set(KINDS) == set(OPTIONS["controller.type"])
    assert all(isinstance(k, PlantKind) for k in KINDS.values())
    a, b = plants
    assert kind_of(a) is PID_SERVO and kind_of(b) is STATE_FEEDBACK_DRIVE


def test_an_unknown_kind_is_one_clear_message(plants):
    a, _ = plants
    bad = a.replace(options={"controller.type": "pid"})
    object.__setattr__(bad, "options", {**bad.options, "controller.type": "pd"})
    with pytest.raises(InputError, match="controller.type 'pd' is not a plant kind; did you mean 'pid'"):
        kind_of(bad)


def test_each_kind_closes_its_own_loop(plants):
    """The same 2 % step: the PID servo's loop records its PID demand, the drive's loop its observers' columns."""
    a, b = plants
    for cfg, x0, extra in ((a, 0.08, "command_demand"), (b, 0.15, "friction_estimate")):
        stroke = cfg.p("cylinder.stroke")
        df = simulate(cfg, Scenario(duration=1.0, initial_position=x0, reference=steps("2%@0.1s", x0, stroke)))
        assert extra in df.columns
        # both settle onto the 2 % step: within their own steady band (stall band of the PID; 0.5 mm, docs/plant-b.md)
        band = max(stall_error(cfg), 0.5e-3) + 0.2e-3
        assert abs(df.position_true.iloc[-1] - (x0 + 0.02 * stroke)) < band
    assert "friction_estimate" not in simulate(a, Scenario(0.05, 0.08)).columns


def test_a_plant_only_run_is_the_same_loop_for_every_kind(plants):
    """A valve-command run has no controller: plant B's runs through the same core as plant A's."""
    _, b = plants
    from compliance.simulation.profiles import Profile
    from compliance.simulation.pid_loop import simulate_pid

    sc = Scenario(duration=0.2, initial_position=0.15, command=Profile(np.array([0.0, 0.2]), np.array([5.5, 5.5])))
    assert np.array_equal(simulate(b, sc).to_numpy(), simulate_pid(b, sc).to_numpy())


def test_the_drive_has_no_stall_band_and_the_servo_its_dead_zone_one(plants):
    a, b = plants
    assert PID_SERVO.stall_error(a) == pytest.approx(stall_error(a)) and PID_SERVO.stall_error(a) > 0.0
    assert STATE_FEEDBACK_DRIVE.stall_error(b) == 0.0


def test_only_the_servo_has_a_linear_model_and_a_replay(plants):
    from compliance.linear.analysis import analyse
    from compliance.linear.nlsys_loop import controller_nlsys

    a, b = plants
    assert PID_SERVO.linear_support(a) is None and PID_SERVO.diagnosis_support(a) is None
    with pytest.raises(InputError, match="state_feedback.*PID only"):
        analyse(b, 0.15)
    with pytest.raises(InputError, match="state_feedback.*PID only"):
        controller_nlsys(b)
    from compliance.diagnosis.servo.stage import check_effects

    with pytest.raises(InputError, match="replay a closed-loop recording with the PID loop"):
        check_effects(b, None)
    assert check_effects(a, ["valve_offset"]) == ["valve_offset"]
    # validate's replay is the same engine: a closed-loop recording of the drive is refused, not replayed by the PID
    import numpy as np
    import pandas as pd

    from compliance.validation.replay import prepare_replay

    t = np.arange(400) * 1e-3
    frame = pd.DataFrame({"time": t, "position": np.full(t.size, 0.1), "reference": np.full(t.size, 0.1)})
    with pytest.raises(InputError, match="replay a closed-loop recording with the PID loop"):
        prepare_replay(b, frame, {})


def test_remedies_change_the_kind_s_own_settings(plants):
    from compliance.sweep.check_remedies import default_space

    a, b = plants
    for cfg, kind in ((a, PID_SERVO), (b, STATE_FEEDBACK_DRIVE)):
        paths = {adj.param.path for adj in default_space(cfg)}
        assert paths and paths <= set(kind.remedy_space)
    assert PID_SERVO.setpoint_limiter and not STATE_FEEDBACK_DRIVE.setpoint_limiter


def test_the_tracking_loop_runs_the_kind_s_controller(plants):
    a, b = plants
    none = {"pid": False, "without_compensation": False}
    assert PID_SERVO.axis_controller(a, none) == ("pid", False, "PID")
    assert STATE_FEEDBACK_DRIVE.axis_controller(b, none) == ("state_feedback", True, "state feedback + friction compensation")
    assert STATE_FEEDBACK_DRIVE.axis_controller(b, {**none, "without_compensation": True})[:2] == ("state_feedback", False)
    assert STATE_FEEDBACK_DRIVE.axis_controller(b, {**none, "pid": True})[:2] == ("pid", False)

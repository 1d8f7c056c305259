"""compliance.linear.nlsys / nlsys_loop: govcheck plants, controller and loop as python-control objects."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

control = pytest.importorskip("control")

from compliance.errors import InputError  # noqa: E402
from compliance.linear.analysis import analyse, margins  # noqa: E402
from compliance.linear.maps import viscous_friction_variant  # noqa: E402
from compliance.linear.nlsys import INPUT, operating_point, to_nlsys, to_statespace  # noqa: E402
from compliance.linear.nlsys_loop import closed_loop_nlsys, controller_nlsys, find_rest_point  # noqa: E402
from compliance.linear.trim import valve_gain  # noqa: E402
from compliance.model.config import load_plant  # noqa: E402
from compliance.simulation import Scenario  # noqa: E402
from compliance.plants import simulate  # noqa: E402
from compliance.simulation.profiles import Profile  # noqa: E402

X_OP, LOAD = 0.136, 11400.0
DOC = Path(__file__).resolve().parents[2] / "docs" / "python-control.md"


@pytest.fixture(scope="module")
def cfg():
    return load_plant("plant-a")


def test_only_active_states_with_units_and_params(cfg):
    sys = to_nlsys(cfg, load=LOAD)
    # plant A: LuGre friction, no effect on: the 4 pneumatic-mechanical states and one bristle
    assert sys.state_labels == ["position_m", "velocity_m_s", "pressure_a_Pa", "pressure_b_Pa", "bristle_1_m"]
    assert sys.input_labels == [INPUT] and sys.output_labels[:3] == ["position_m", "pressure_a_Pa", "pressure_b_Pa"]
    assert sys.params["p_supply"] == pytest.approx(8e5) and sys.params["mass"] == pytest.approx(30.0)
    heat = to_nlsys(cfg.replace(effects={"heat_transfer": {}}), load=LOAD)
    assert heat.state_labels[4:6] == ["temperature_a_K", "temperature_b_K"] and heat.nstates == 7
    # linearised at rest (valve shut): no zero eigenvalue from a switched-off effect (13 with every
    # state); three remain and are physics: any rest position (nothing at rest depends on x under a
    # constant load), the common pressure level, and how the held force splits between the pressure
    # difference and the bristle's pre-sliding spring (x, z, p_A, p_B all move with v alone)
    x0, u0 = operating_point(cfg, X_OP, LOAD)
    lin = control.linearize(sys, x0, [u0])
    assert int(np.sum(np.abs(np.linalg.eigvals(lin.A)) < 1e-6)) == 3


def test_params_reach_the_right_hand_side(cfg):
    sys = to_nlsys(cfg, load=LOAD)
    x0, u0 = operating_point(cfg, X_OP, LOAD)
    assert abs(sys.dynamics(0.0, x0, [u0])[1]) < 1e-6
    # 10 % more mass: the same net force after opening the valve gives 1/1.1 of the acceleration
    u = [u0 + 2.0]
    x1 = x0.copy()
    x1[2] += 1e4  # 10 kPa more in A: a net force on the piston
    a_ref = sys.dynamics(0.0, x1, u)[1]
    a_heavy = sys.dynamics(0.0, x1, u, params={"mass": 33.0})[1]
    assert a_heavy == pytest.approx(a_ref / 1.1, rel=1e-9)


def test_open_loop_response_equals_the_simulator(cfg):
    """The NonlinearIOSystem IS plant_rhs: a 2 V open-loop run matches govcheck's own RK4 run."""
    sys = to_nlsys(cfg, load=LOAD)
    x0, _ = operating_point(cfg, X_OP, LOAD)
    t = np.linspace(0.0, 0.3, 301)
    r = control.input_output_response(sys, t, np.full_like(t, 2.0), x0, solve_ivp_method="LSODA",
                                      solve_ivp_kwargs={"rtol": 1e-8, "atol": 1e-9})
    df = simulate(cfg, Scenario(duration=0.3, initial_position=X_OP, command=Profile([0.0, 0.0], [2.0, 2.0]), load=LOAD))
    assert r.outputs[0][-1] - X_OP > 5e-3  # 2 V opens the valve past its 0.61 V dead zone: several mm
    # RK4 at 1 ms against an adaptive solver: agree to a micrometre
    assert r.outputs[0][-1] == pytest.approx(df.position_true.iloc[-1], abs=1e-6)
    assert r.outputs[1][-1] == pytest.approx(df.pressure_a.iloc[-1], rel=1e-5)


def test_rest_point_is_the_trim_and_non_physical_guesses_are_refused(cfg):
    sys = to_nlsys(cfg, load=LOAD)
    x, u = find_rest_point(sys, X_OP)
    x_trim, u_trim = operating_point(cfg, X_OP, LOAD)
    assert np.allclose(x, x_trim, rtol=1e-9, atol=1e-12) and u[0] == pytest.approx(u_trim)
    # from another p_B the solver finds the p_A that holds 11.4 kN: (p_A - p_B)(A_cap + A_rod) = F
    x2, _ = find_rest_point(sys, X_OP, pressure_b=3e5)
    assert (x2[2] - x2[3]) * (cfg.piston_area + cfg.rod_side_area) == pytest.approx(LOAD, rel=1e-6)
    with pytest.raises(InputError, match="pressure_a_Pa = 0 Pa abs is not physical"):
        find_rest_point(sys, X_OP, guess=np.zeros(sys.nstates))
    # p_B = 7.5 bar would need p_A above supply to hold the load: refused, not returned
    with pytest.raises(InputError, match="pressure_a_Pa = .* not physical"):
        find_rest_point(sys, X_OP, pressure_b=7.5e5)


def test_closed_loop_nlsys_rests_and_steps_like_the_simulator(cfg):
    loop = closed_loop_nlsys(cfg, load=LOAD)
    assert loop.input_labels == ["reference_m"] and "u_d_V" in loop.output_labels
    assert loop.nstates == 7  # 5 plant states (plant A) + the integral and the filtered position
    x0, _ = operating_point(cfg, X_OP, LOAD)
    xc = np.concatenate([x0, [0.0, X_OP]])
    assert np.max(np.abs(loop.dynamics(0.0, xc, [X_OP])[:2])) < 1e-9  # at rest with the reference on the gate
    # a 5 % step: the continuous loop against the simulator's 1 kHz loop, 63.2 % times within 10 %
    t = np.linspace(0.0, 1.5, 1501)
    ref = np.full_like(t, X_OP + 8e-3)
    r = control.input_output_response(loop, t, ref, xc, solve_ivp_method="LSODA", solve_ivp_kwargs={"max_step": 1e-3})
    df = simulate(cfg, Scenario(1.5, X_OP, reference=Profile([0.0, 0.0], [X_OP + 8e-3, X_OP + 8e-3]), load=LOAD))

    def t63(tt, xx):
        return tt[np.argmax(xx >= X_OP + 0.632 * 8e-3)]

    assert t63(t, r.outputs[0]) == pytest.approx(t63(df.time.to_numpy(), df.position_true.to_numpy()), rel=0.10)


def test_round_trip_reproduces_govcheck_linear(cfg):
    """find_operating_point, linearize, interconnect with govcheck's controller -> govcheck linear's loop."""
    plant = to_nlsys(viscous_friction_variant(cfg), load=LOAD, input="opening")  # the linear model's friction
    assert plant.nstates == 4
    xeq, ueq = find_rest_point(plant, X_OP)
    G = control.linearize(plant, xeq, ueq, copy_names=True)  # forward step: the opening side of the null
    valve = control.ss([], [], [], [[valve_gain(cfg, "opening")]], inputs=["u_d_V"], outputs=["command_opening_1"], name="valve")
    pid = control.linearize(controller_nlsys(cfg), [0.0, X_OP], [X_OP, X_OP], copy_names=True)[0, :]
    loop = control.interconnect([G, valve, pid], inputs=["reference_m"], outputs=["position_m"], check_unused=False)
    a = analyse(cfg, X_OP, LOAD, gain="opening")
    ours = np.sort_complex(np.array([p for p in control.poles(loop) if abs(p) > 1e-6]))
    theirs = np.sort_complex(np.array([p for p in control.poles(a.closed_loop) if abs(p) > 1e-6]))
    assert ours.shape == theirs.shape and np.allclose(ours, theirs, rtol=1e-4)
    # the loop broken at u_d (valve, plant, controller's measurement path): govcheck's continuous margins
    L = control.series(valve, G[0, 0], -pid[0, 1])
    floor = 10.0 * cfg.p("controller.ki") / cfg.p("controller.kp") / (2 * np.pi)
    m = margins(L, floor)
    assert m["phase_margin_deg"] == pytest.approx(a.figures["phase_margin_deg_continuous"], abs=0.1)
    assert m["gain_margin_db"] == pytest.approx(a.figures["gain_margin_db_continuous"], abs=0.05)


def test_documented_example_runs(cfg, capsys):
    """docs/python-control.md's example runs as written and prints what the page says."""
    code = "\n".join(re.findall(r"```python\n(.*?)```", DOC.read_text(), flags=re.S))
    exec(compile(code, str(DOC), "exec"), {})
    out = capsys.readouterr().out
    for line in re.findall(r"^# (.+)$", code, flags=re.M):
        if line.startswith("->"):
            assert line[3:] in out, line


def test_state_feedback_controller_is_refused_with_a_clear_error():
    with pytest.raises(InputError, match="state_feedback.*PID only"):
        controller_nlsys(load_plant("plant-b"))

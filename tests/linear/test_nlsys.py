"""compliance.linear.nlsys: govcheck plants as python-control objects."""

from __future__ import annotations

import numpy as np
import pytest

control = pytest.importorskip("control")

from compliance.linear.analysis import analyse  # noqa: E402
from compliance.linear.nlsys import OUTPUTS, operating_point, to_nlsys, to_statespace  # noqa: E402
from compliance.model.config import load_plant  # noqa: E402
from compliance.model.vector_slots import STATE_NAMES  # noqa: E402
from compliance.simulation import Scenario, simulate  # noqa: E402
from compliance.simulation.profiles import Profile  # noqa: E402

X_OP, LOAD = 0.136, 11400.0


@pytest.fixture(scope="module")
def cfg():
    return load_plant("plant-a")


def test_named_signals_and_rest_at_the_operating_point(cfg):
    sys = to_nlsys(cfg, load=LOAD)
    assert isinstance(sys, control.NonlinearIOSystem)
    assert sys.input_labels == ["valve_command"] and sys.output_labels == list(OUTPUTS)
    assert sys.state_labels == list(STATE_NAMES)
    x0, u0 = operating_point(cfg, X_OP, LOAD)
    dx = sys.dynamics(0.0, x0, [u0])
    # at rest: no velocity, no acceleration, no pressure change (relative to p_s per second)
    assert abs(dx[0]) < 1e-12 and abs(dx[1]) < 1e-6 and np.all(np.abs(dx[2:4]) < 1e-6 * 8e5)
    out = sys.output(0.0, x0, [u0])
    # the pneumatic force holds the 11.4 kN load
    assert out[OUTPUTS.index("pneumatic_force")] == pytest.approx(LOAD, rel=1e-6)


def test_open_loop_response_equals_the_simulator(cfg):
    """The NonlinearIOSystem IS plant_rhs: a 2 V open-loop run matches govcheck's own RK4 run."""
    sys = to_nlsys(cfg, load=LOAD)
    x0, _ = operating_point(cfg, X_OP, LOAD)
    t = np.linspace(0.0, 0.3, 301)
    r = control.input_output_response(sys, t, np.full_like(t, 2.0), x0, solve_ivp_method="LSODA",
                                      solve_ivp_kwargs={"rtol": 1e-8, "atol": 1e-9})
    df = simulate(cfg, Scenario(duration=0.3, initial_position=X_OP, command=Profile([0.0, 0.0], [2.0, 2.0]), load=LOAD))
    moved = r.outputs[0][-1] - X_OP
    assert moved > 5e-3  # 2 V opens the valve past its 0.61 V dead zone: several mm in 0.3 s
    # RK4 at 1 ms against an adaptive solver: agree to a micrometre
    assert r.outputs[0][-1] == pytest.approx(df.position_true.iloc[-1], abs=1e-6)
    assert r.outputs[1][-1] == pytest.approx(df.pressure_a.iloc[-1], rel=1e-5)


def test_statespace_is_the_linear_analysis(cfg):
    G = to_statespace(cfg, X_OP, LOAD)
    assert isinstance(G, control.StateSpace)
    assert G.state_labels == ["position", "velocity", "pressure_a", "pressure_b"] and G.input_labels == ["u_d"]
    Gm = to_statespace(cfg, X_OP, LOAD, minimal=True)
    assert Gm.nstates == 3  # the common pressure level is not seen from u_d to x
    a = analyse(cfg, X_OP, LOAD)
    wn = a.figures["natural_frequency_hz"] * 2 * np.pi
    poles = control.poles(Gm)
    assert max(abs(p) for p in poles) == pytest.approx(wn, rel=1e-3)  # the pneumatic resonance
    # closed loop with the configured PID (continuous): 63.2 % time within 10 % of govcheck's dominant pole
    kp, ki, kd = (cfg.p(f"controller.{k}") for k in ("kp", "ki", "kd"))
    wf = 2 * np.pi * cfg.p("controller.filter_cutoff")
    s = control.tf("s")
    T = control.feedback((kp + ki / s) * Gm, 1 + kd * s / (kp + ki / s) / (1 + s / wf))
    y = control.step_response(T, np.linspace(0, 2, 4001))
    t63 = y.time[np.argmax(y.outputs >= 0.632 * y.outputs[-1])]
    assert t63 == pytest.approx(a.figures["dominant_time_constant"], rel=0.1)

"""The governor's set-point rate limiter: ramp following, rates honoured both ways, end zone, no wind-up."""

from __future__ import annotations

import numpy as np
import pytest

from compliance.errors import InputError
from compliance.model.config import load_plant
from compliance.model.pid_controller import limiter_sample, rate_limited_setpoint
from compliance.model.plant_vector import parameter_vector
from compliance.simulation import Scenario
from compliance.plants import simulate
from compliance.simulation.profiles import Profile, steps

STROKE = 0.160
TS = 1e-3
RATE_OPEN, RATE_CLOSE = 0.020, 0.030  # m/s: 8 s and 5.3 s full strokes


@pytest.fixture(scope="module")
def cfg():
    return load_plant("plant-a")


def limited(cfg, **rates):
    return cfg.replace(params={f"controller.{k}": v for k, v in rates.items()})


def _run_limiter(target, r0, **kw):
    out = np.empty(target.size)
    r = r0
    for k, t in enumerate(target):
        r = rate_limited_setpoint(t, r, kw.get("up", 0.0), kw.get("down", 0.0), kw.get("end_rate", 0.0),
                                  kw.get("end_width", 0.0), STROKE, TS)
        out[k] = r
    return out


def test_rates_honoured_both_directions_and_target_reached():
    target = np.r_[np.full(100, 0.10), np.full(3000, 0.02)]
    r = _run_limiter(target, 0.02, up=RATE_OPEN, down=RATE_CLOSE)
    d = np.diff(r) / TS
    assert d.max() == pytest.approx(RATE_OPEN, rel=1e-9)
    assert d.min() == pytest.approx(-RATE_CLOSE, rel=1e-9)
    # 80 mm up at 20 mm/s takes 4.0 s: not reached in the 0.1 s the target stays up, then back down at 30 mm/s
    assert r[99] == pytest.approx(0.02 + RATE_OPEN * 0.1, abs=1e-12)
    assert r[-1] == 0.02


def test_no_wind_up_the_state_never_passes_the_set_point():
    rng = np.random.default_rng(3)
    target = np.repeat(rng.uniform(0.0, STROKE, 40), 50)  # a new set-point every 50 ms, faster than the rates allow
    r = _run_limiter(target, target[0], up=RATE_OPEN, down=RATE_CLOSE)
    prev = np.r_[target[0], r[:-1]]
    # each sample moves toward the set-point and stops at it: |target - r| never grows, r never overshoots
    assert np.all(np.abs(target - r) <= np.abs(target - prev) + 1e-15)
    assert np.all((r - prev) * (target - prev) >= 0.0)
    assert np.all(np.abs(r - prev) <= RATE_CLOSE * TS * (1 + 1e-12))


def test_end_zone_rate_near_each_end_stop():
    width, slow = 0.016, 0.004
    down = _run_limiter(np.zeros(10000), 0.080, up=RATE_OPEN, down=RATE_CLOSE, end_rate=slow, end_width=width)
    prev = np.r_[0.080, down[:-1]]
    speed = (prev - down) / TS
    outside, inside = down > width, (prev <= width) & (down > 0.0)
    assert np.allclose(speed[outside], RATE_CLOSE)
    assert np.allclose(speed[inside], slow)
    # 64 mm at 30 mm/s then 16 mm at 4 mm/s: 2.13 s + 4.0 s to reach the closed end
    assert np.argmax(down <= 0.0) * TS == pytest.approx(0.064 / RATE_CLOSE + width / slow, abs=2 * TS)
    assert down.min() == 0.0 and np.all(np.diff(down) <= 0.0)  # stops at the set-point, never past it
    up = _run_limiter(np.full(10000, STROKE), 0.080, up=RATE_OPEN, down=RATE_CLOSE, end_rate=slow, end_width=width)
    assert np.argmax(up >= STROKE) * TS == pytest.approx(0.064 / RATE_OPEN + width / slow, abs=2 * TS)


def test_plant_follows_the_limited_ramp(cfg):
    """A 50 % step with a 20 mm/s opening limit: the gate moves at the limited rate, not at the valve's."""
    c = limited(cfg, setpoint_opening_rate=RATE_OPEN, setpoint_closing_rate=RATE_CLOSE)
    sc = Scenario(duration=6.0, initial_position=0.04, reference=steps("50%@0.5s", 0.04, STROKE), load=3000.0)
    x = simulate(c, sc)["position_true"].to_numpy()
    t = np.arange(x.size) * TS
    mid = (t > 1.5) & (t < 4.0)  # well inside the 4 s ramp, after the servo has caught up
    slope = np.polyfit(t[mid], x[mid], 1)[0]
    assert slope == pytest.approx(RATE_OPEN, rel=0.03)  # follows the ramp to 3 %
    lag = (0.04 + RATE_OPEN * (t[mid] - 0.5)) - x[mid]
    assert np.abs(lag).max() < 0.004  # tracking a 20 mm/s ramp within 4 mm (K_P = 280 V/m: ~1.5 V demand)
    assert x[-1] == pytest.approx(0.12, abs=0.002)
    free = simulate(cfg, sc)["position_true"].to_numpy()
    assert np.argmax(free > 0.10) < 0.5 * np.argmax(x > 0.10)  # without the limiter it gets there much sooner


def test_closing_rate_honoured_in_the_plant(cfg):
    c = limited(cfg, setpoint_opening_rate=RATE_OPEN, setpoint_closing_rate=RATE_CLOSE)
    sc = Scenario(duration=5.0, initial_position=0.12, reference=steps("-50%@0.5s", 0.12, STROKE), load=3000.0)
    df = simulate(c, sc)
    v = np.gradient(df["position_true"].to_numpy(), TS)
    assert -v.min() < 1.25 * RATE_CLOSE  # the limited set-point bounds the speed (no surge past 25 %)
    t = np.arange(v.size) * TS
    assert np.median(v[(t > 1.5) & (t < 2.5)]) == pytest.approx(-RATE_CLOSE, rel=0.05)


def test_off_and_never_binding_are_bit_identical(cfg):
    sc = Scenario(duration=2.0, initial_position=0.08, reference=steps("5%@0.3s,-10%@1.0s", 0.08, STROKE), load=3000.0)
    off = simulate(cfg, sc).to_numpy()
    wide = simulate(limited(cfg, setpoint_opening_rate=1e3, setpoint_closing_rate=1e3), sc).to_numpy()
    assert np.array_equal(off, wide)


def test_limiter_refused_on_state_feedback():
    b = load_plant("plant-b")
    with pytest.raises(InputError, match="option of the PID controller"):
        from compliance.model.config import plant_from_dict
        import tomllib
        data = tomllib.loads(open(b.path).read()) if b.path else None
        data["controller"]["setpoint_opening_rate"] = "10 mm/s"
        plant_from_dict(data, "plant-b.toml")


def test_lead_limit_holds_the_set_point_near_a_stuck_gate(cfg):
    """Ramp hold: a gate held at the closed end keeps the limited set-point within the lead limit."""
    lead = 0.004
    P = parameter_vector(limited(cfg, setpoint_opening_rate=RATE_OPEN, setpoint_lead_limit=lead))
    r, gate = 0.0, 0.0
    for _ in range(2000):  # 2 s stuck: without the hold the set-point would be 40 mm ahead
        r = limiter_sample(P, STROKE, r, gate, TS)
    assert r == pytest.approx(lead, abs=RATE_OPEN * TS)
    for k in range(1, 501):  # the gate moves at 10 mm/s: the set-point follows it, never further ahead than the lead
        gate = 0.01 * k * TS
        r_new = limiter_sample(P, STROKE, r, gate, TS)
        assert r <= r_new <= max(r, gate + lead) + 1e-15
        r = r_new
    assert r == pytest.approx(0.005 + lead, abs=RATE_OPEN * TS)
    # closing (not rate-limited here): held while the gate lags 40 mm behind, never pushed back up past where it was
    assert limiter_sample(P, 0.05, 0.06, 0.10, TS) == 0.06
    assert limiter_sample(P, 0.05, 0.06, 0.058, TS) == pytest.approx(0.058 - lead)


def test_full_stroke_goes_through_the_governor(cfg):
    """With a limiter the full-stroke procedure steps the set-point: closing at 20 mm/s takes 8 s (25-75 % rule)."""
    from compliance import metrics as M
    from compliance.procedures.scenarios import full_command_stroke
    from compliance.requirements.loading import load_requirements

    op = load_requirements("shpp-400kw").operating_points["governor-setup"]
    c = limited(cfg, setpoint_opening_rate=RATE_OPEN, setpoint_closing_rate=RATE_OPEN, setpoint_lead_limit=0.004)
    df = full_command_stroke(c, op, "closing", "full", 12.0, True)
    t, x = M.frame_columns(df, "time", "position")
    T = M.stroke_time(t, x, STROKE, "closing")[0]
    assert T == pytest.approx(STROKE / RATE_OPEN, rel=0.05)
    assert M.speed_extremes(t, x)[0] < 1.25 * RATE_OPEN  # the start-of-stroke surge is gone (at full command: > 100 mm/s)

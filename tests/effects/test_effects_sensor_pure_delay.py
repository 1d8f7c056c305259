"""A sensor with a pure delay and no lag reads exactly the delayed true position."""

import numpy as np

from compliance.model.config import load_plant
from compliance.simulation.profiles import Profile
from compliance.simulation import Scenario
from compliance.plants import simulate


def test_pure_delay_reads_the_delayed_position():
    td = 0.004  # four controller samples
    cfg = load_plant("plant-a").replace(effects={"sensor_lag": {"time_constant": 0.0, "delay": td}})
    df = simulate(cfg, Scenario(duration=0.5, initial_position=0.04, command=Profile.constant(3.0), load=2000.0))
    x = df.position_true.to_numpy()
    m = df.position.to_numpy()
    # the history is sampled on the integration grid and interpolated linearly: exact at grid points
    assert np.allclose(m[4:], x[:-4], atol=1e-12)

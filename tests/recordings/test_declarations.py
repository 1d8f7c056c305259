"""A sidecar's instrument declarations are held to the data they describe (compliance/recordings/instruments.py).

Each check has its boundary tested both ways: what a logger and transducer can truly do passes (a rate
within its tolerance, a range the data stay inside, a gauge range on absolute pressures, a delay of
some samples), a declaration the data contradict is refused with the figures.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from compliance.errors import InputError
from compliance.recordings.instruments import (RANGE_MARGIN, RATE_TOLERANCE, check_channel_delays,
                                                check_channel_ranges, check_declarations, check_logger_rate)


@pytest.fixture
def frame():
    t = np.arange(1000) * 1e-3  # 1 kHz, 0.999 s
    return pd.DataFrame({"time": t, "position": 0.04 + 0.04 * t, "pressure_a": np.full(t.size, 6e5)})


def test_logger_rate_within_tolerance_passes_and_another_rate_is_refused(frame):
    check_logger_rate(frame, {"logger": {"rate": 1000.0 * (1 + 0.5 * RATE_TOLERANCE)}}, "s.toml")
    with pytest.raises(InputError, match=r"s\.toml: logger\.rate = 250 Hz, and the time stamps are 1000 Hz apart"):
        check_logger_rate(frame, {"logger": {"rate": 250.0}}, "s.toml")
    # a rate read from a logger's comment line is what the logger can do, not this file's declaration
    check_logger_rate(frame, {"logger": {"rate": 250.0, "source": "comment lines"}}, "s.toml")


def test_channel_range_holds_the_data_with_its_margin(frame):
    # position 40..80 mm: a 0..80 mm transducer (and one 5 % short of it) records it; a 0..50 mm one cannot
    check_channel_ranges(frame, {"channels": {"position": {"range": [0.0, 0.08]}}}, "s.toml")
    check_channel_ranges(frame, {"channels": {"position": {"range": [0.0, 0.08 / (1 + 0.9 * RANGE_MARGIN)]}}}, "s.toml")
    with pytest.raises(InputError, match=r"channels\.position\.range = 0 \.\. 50 mm, and the recording's 'position' "
                                         r"reaches 79.96 mm"):
        check_channel_ranges(frame, {"channels": {"position": {"range": [0.0, 0.05]}}}, "s.toml")


def test_pressure_range_may_be_gauge_or_absolute(frame):
    check_channel_ranges(frame, {"channels": {"pressure_a": {"range": [0.0, 10e5]}}}, "s.toml")  # 0-10 bar: either
    check_channel_ranges(frame, {"channels": {"pressure_a": {"range": [0.0, 5e5]}}}, "s.toml")  # 0-5 bar gauge holds 6 bar abs
    with pytest.raises(InputError, match="gauge or absolute"):
        check_channel_ranges(frame, {"channels": {"pressure_a": {"range": [0.0, 2e5]}}}, "s.toml")


def test_delay_shorter_than_the_recording(frame):
    check_channel_delays(frame, {"channels": {"position": {"delay": 0.005}}}, "s.toml")
    with pytest.raises(InputError, match=r"channels\.position\.delay = 5 s is as long as the whole recording \(0\.999 s\)"):
        check_channel_delays(frame, {"channels": {"position": {"delay": 5.0}}}, "s.toml")


def test_declarations_without_instruments_pass(frame):
    check_declarations(frame, {}, "s.toml")
    check_declarations(frame, {"channels": {"force": {"range": [0.0, 1.0]}}}, "s.toml")  # a channel not recorded

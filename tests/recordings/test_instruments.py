"""The logger and channel tables of a recording's sidecar, and the logger's own comment lines."""

from __future__ import annotations

import gzip

import pytest

from compliance.errors import InputError
from compliance.recordings.instruments import instrument_facts, logger_from_comments
from compliance.recordings.reader import read_recording

CSV = "time,position,reference,valve_command\n" + "".join(f"{k*0.004:.3f},0.07,0.07,0.0\n" for k in range(100))


def _write(tmp_path, sidecar: str | None, comments: str = ""):
    path = tmp_path / "rec.csv.gz"
    with gzip.open(path, "wt") as fh:
        fh.write(comments + CSV)
    if sidecar is not None:
        (tmp_path / "rec.toml").write_text('plant = "plant-a"\n' + sidecar)
    return path


def test_sidecar_logger_and_channels_become_si_floats(tmp_path):
    side = """
[logger]
rate = "250 Hz"
anti_alias_cutoff = "80 Hz"
[channels.position]
resolution = "50 um"
delay = "4 ms"
[channels.pressure_b]
gain = 0.99
offset = "2 kPa"
range = ["0 bar", "10 bar"]
"""
    _, meta = read_recording(_write(tmp_path, side))
    assert meta["logger"] == {"rate": 250.0, "anti_alias_cutoff": 80.0}
    assert meta["channels"]["position"] == pytest.approx({"resolution": 5e-5, "delay": 0.004})
    assert meta["channels"]["pressure_b"] == {"gain": 0.99, "offset": 2000.0, "range": [0.0, 1e6]}


@pytest.mark.parametrize("side, match", [
    ("[logger]\nanti_alias_cutof = 80.0\n", "logger.anti_alias_cutof: unknown key; did you mean 'anti_alias_cutoff'"),
    ("[logger]\nanti_alias_cutoff = \"3 ms\"\n", "logger.anti_alias_cutoff"),
    ("[channels.positon]\nresolution = 1e-5\n", "unknown channel 'positon'"),
    ("[channels.position]\nresolution = \"10 kPa\"\n", "channels.position.resolution"),
    ("[logger]\nanti_alias_order = 2\n", "only a first-order anti-alias filter"),
])
def test_bad_logger_facts_are_refused_at_the_edge(tmp_path, side, match):
    with pytest.raises(InputError, match=match):
        read_recording(_write(tmp_path, side))


def test_comment_lines_state_the_logger_only_in_the_recognised_phrases(tmp_path):
    daq = "# portable DAQ, 500 Hz, first-order anti-alias filter 150 Hz on every analog input\n"
    _, meta = read_recording(_write(tmp_path, None, daq))
    assert meta["logger"] == {"rate": 500.0, "anti_alias_cutoff": 150.0, "source": "comment lines"}
    _, meta = read_recording(_write(tmp_path, "[logger]\nanti_alias_cutoff = 200.0\n", daq))
    assert meta["logger"] == {"anti_alias_cutoff": 200.0}  # the sidecar wins
    assert logger_from_comments(["filtered at about 100 Hz, maybe"]) == {}
    assert instrument_facts({"plant": "x"}, "s.toml") == {"plant": "x"}

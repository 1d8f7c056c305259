"""Files as people export them (Excel, European loggers, clocks, shared folders) read like their plain twins.

Each variant holds the same 0.2 s recording of the bad-input workspace as its plain canonical
CSV; it must read to the same canonical columns (time relative to its first sample, rtol 1e-9
on values written with 9 significant digits; 1e-6 s on times that went through a clock of
0.24 us resolution) and `govcheck validate` against plant A must give the same verdict and the
same fit numbers as for the plain twin.
"""

from __future__ import annotations

import datetime as dt
import json

import numpy as np
import pandas as pd
import pytest

from compliance.cli import main
from compliance.recordings.reader import read_recording
from tests.bad_inputs import workspace as W

START = 1709648521.0  # 2024-03-05T14:22:01Z
BOM = "\ufeff"


def _clock(text: str, fmt, sep=",", decimal=".") -> str:
    lines = text.splitlines()
    out = [lines[0].replace(",", sep)]
    for line in lines[1:]:
        cells = [c.replace(".", decimal) for c in line.split(",")]
        cells[0] = fmt(float(line.split(",")[0]))
        out.append(sep.join(cells))
    return "\n".join(out) + "\n"


def _iso(t: float) -> str:
    return (dt.datetime(2024, 3, 5, 14, 22, 1) + dt.timedelta(seconds=t)).strftime("%Y-%m-%d %H:%M:%S.%f")[:-3]


def _european(t: float) -> str:
    return (dt.datetime(2024, 3, 5, 14, 22, 1) + dt.timedelta(seconds=t)).strftime("%d.%m.%Y %H:%M:%S,%f")[:-3]


PLAIN = W.csv_text()
VARIANTS = {
    "bom.csv": BOM + PLAIN,
    "tab.tsv": PLAIN.replace(",", "\t"),
    "tab.csv": PLAIN.replace(",", "\t"),
    "european.csv": PLAIN.replace(",", ";").replace(".", ","),
    "european-tab.txt": PLAIN.replace(",", "\t").replace(".", ","),
    "epoch.csv": _clock(PLAIN, lambda t: repr(START + t)),
    "datetime.csv": _clock(PLAIN, _iso),
    "datetime-eu.csv": _clock(PLAIN, _european, sep=";", decimal=","),
}


@pytest.fixture()
def ws(tmp_path):
    W.build(tmp_path)
    for name, text in VARIANTS.items():
        (tmp_path / name).write_text(text, encoding="utf-8")
        stem = name.rsplit(".", 1)[0]
        (tmp_path / f"{stem}.toml").write_text(BOM + W.SIDECAR, encoding="utf-8")
    return tmp_path


@pytest.mark.parametrize("name", sorted(VARIANTS))
def test_variant_reads_like_plain(ws, name):
    plain, _ = read_recording(ws / "rec.csv")
    frame, meta = read_recording(ws / name)
    assert list(frame.columns) == list(plain.columns)
    for col in plain.columns:
        tol = dict(rtol=0, atol=1e-6) if col == "time" else dict(rtol=1e-9, atol=0)
        np.testing.assert_allclose(frame[col], plain[col], **tol, err_msg=col)
    assert meta["plant"] == "plant-a"  # the BOM-prefixed sidecar was read
    if "epoch" in name or "datetime" in name:
        assert meta["time_start"]["unix"] == pytest.approx(START, abs=1e-3)
        assert meta["time_start"]["utc"] == "2024-03-05T14:22:01.000Z"
    else:
        assert "time_start" not in meta


def test_parquet_datetime_time_made_relative(ws):
    cols = W.recording_columns()
    stamps = pd.to_datetime(START + cols["time"], unit="s")
    pd.DataFrame({**cols, "time": stamps}).to_parquet(ws / "clock.parquet", index=False)
    frame, meta = read_recording(ws / "clock.parquet")
    np.testing.assert_allclose(frame["time"], cols["time"], rtol=0, atol=1e-6)
    assert meta["time_start"]["utc"].startswith("2024-03-05T14:22:01")


def test_parquet_epoch_seconds_made_relative(ws):
    cols = W.recording_columns()
    pd.DataFrame({**cols, "time": START + cols["time"]}).to_parquet(ws / "epoch.parquet", index=False)
    frame, meta = read_recording(ws / "epoch.parquet")
    np.testing.assert_allclose(frame["time"], cols["time"], rtol=0, atol=1e-6)
    assert meta["time_start"]["unix"] == START


def test_symlinked_recording_finds_sidecar_beside_target(ws):
    shared = ws / "shared"
    shared.mkdir()
    (shared / "run.csv").write_text(PLAIN, encoding="utf-8")
    (shared / "run.toml").write_text(W.SIDECAR, encoding="utf-8")
    (ws / "run.csv").symlink_to(shared / "run.csv")
    _, meta = read_recording(ws / "run.csv")
    assert meta["conditions"]["load_force"] == 7000.0


def _validate(ws, monkeypatch, recording, plant="plant.toml"):
    monkeypatch.chdir(ws)
    out = ws / "out" / f"{recording}.json"
    assert main(["validate", plant, recording, "--json", str(out), "-q"]) == 0
    return json.loads(out.read_text(encoding="utf-8"))


@pytest.mark.parametrize("name", ["bom.csv", "tab.tsv", "european.csv", "epoch.csv", "datetime.csv"])
def test_validate_against_plant_a_like_the_plain_twin(ws, monkeypatch, name):
    (ws / "bom-plant.toml").write_text(BOM + W.PLANT_A, encoding="utf-8")
    plain = _validate(ws, monkeypatch, "rec.csv")
    got = _validate(ws, monkeypatch, name, plant="bom-plant.toml")
    assert got["summary"] == plain["summary"]
    for mode, m in plain["modes"].items():
        for signal, fit in m["fits"].items():
            for key, value in fit.items():
                if isinstance(value, float):  # same samples replayed: same errors to well below the 1 um position noise
                    assert got["modes"][mode]["fits"][signal][key] == pytest.approx(value, rel=1e-6, abs=1e-9), (signal, key)


def test_bom_in_requirement_sweep_and_column_map(ws, monkeypatch, capsys):
    from compliance.recordings.column_map import load_column_map
    from compliance.requirements import load_requirements

    (ws / "bom-req.toml").write_text(BOM + W.REQUIREMENTS, encoding="utf-8")
    (ws / "bom-map.toml").write_text(BOM + W.COLUMN_MAP, encoding="utf-8")
    assert load_requirements(ws / "bom-req.toml").name == "tiny"
    assert load_column_map(ws / "bom-map.toml").spec("position").unit == "mm"
    from compliance.sweep.candidates.spec import load_sweep
    from tests.bad_inputs.cases import SWEEP

    (ws / "bom-sweep.toml").write_text(BOM + SWEEP, encoding="utf-8")
    assert load_sweep(ws / "bom-sweep.toml").name == "tiny"

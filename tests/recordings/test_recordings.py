"""Recording readers: every format to canonical SI columns, and the bad-file catalogue.

Expected values are computed independently in each test (unit factors by hand: 1 mm =
1e-3 m, 1 bar = 1e5 Pa, gauge + 101325 Pa), never copied from the reader's output. Float
comparisons use rtol 1e-12 where only exact unit factors are involved.
"""

from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import scipy.io

from compliance.recordings.column_map import load_column_map
from compliance.errors import InputError
from compliance.recordings.reader import read_recording, sidecar_path

DATA = Path(__file__).resolve().parents[1] / "data"
ATM = 101325.0
ZILLEN_NEEDS = ("time", "position", "pressure_a", "force")

CANONICAL = """# bench run 7, logged by hand
time,position,reference,valve_command,pressure_a,pressure_b,supply_pressure
0.000,0.0600,0.0600,0.00,600000.0,300000.0,800000.0
# a comment in the middle
0.001,0.0601,0.0600,0.50,601000.0,299000.0,800000.0
0.002,0.0603,0.0600,0.70,602000.0,298000.0,800000.0
"""

SIDECAR = """plant = "plant-a"
description = "2 % step"
[conditions]
load_force = 11400.0
supply_pressure = "8 bar abs"
initial_position = "136 mm"
[controller]
kp = 280.0
"""


def _write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


# ----------------------------------------------------------------------------- formats
def test_canonical_csv_with_comments_and_sidecar(tmp_path):
    rec = _write(tmp_path / "run7.csv", CANONICAL)
    _write(tmp_path / "run7.toml", SIDECAR)
    df, meta = read_recording(rec)
    assert list(df.columns) == ["time", "position", "reference", "valve_command", "pressure_a", "pressure_b",
                                "supply_pressure"]
    np.testing.assert_allclose(df["time"], [0.0, 0.001, 0.002], rtol=0, atol=0)
    np.testing.assert_allclose(df["pressure_b"], [3.0e5, 2.99e5, 2.98e5], rtol=1e-12)
    assert meta["plant"] == "plant-a"
    assert meta["description"] == "2 % step"  # free text is never parsed as a quantity
    assert meta["conditions"]["load_force"] == 11400.0
    assert meta["conditions"]["supply_pressure"] == pytest.approx(8e5, rel=1e-12)
    assert meta["conditions"]["initial_position"] == pytest.approx(0.136, rel=1e-12)
    assert meta["source_path"] == str(rec) and meta["format"] == "csv"


def test_csv_gz_sidecar_is_stem_toml(tmp_path):
    rec = tmp_path / "run8.csv.gz"
    with gzip.open(rec, "wt", encoding="utf-8") as fh:
        fh.write(CANONICAL)
    _write(tmp_path / "run8.toml", 'plant = "plant-b"\n')
    assert sidecar_path(rec) == tmp_path / "run8.toml"
    df, meta = read_recording(rec)
    assert len(df) == 3 and meta["plant"] == "plant-b" and meta["format"] == "csv.gz"


def test_column_map_units_gauge_ms_delimiter_drop_first(tmp_path):
    text = "logger v2 export\nunits below\nt_ms;x_mm;u_V;pA_bar_g;raw_counts\n"
    rows = [(0, 10.0, 0.1, 5.0, 100), (1, 10.5, 0.2, 5.1, 200), (2, 11.0, 0.3, 5.2, 300), (4, 11.5, 0.4, 5.3, 400)]
    text += "".join(f"{a};{b};{c};{d};{e}\n" for a, b, c, d, e in rows)
    rec = _write(tmp_path / "logger.txt", text)
    cmap = {
        "delimiter": ";", "skip_rows": 2, "drop_first": 1, "time_unit": "ms",
        "columns": {
            "time": {"column": "t_ms"},
            "position": {"column": "x_mm", "unit": "mm"},
            "valve_command": {"column": 2, "unit": "V"},
            "pressure_a": {"column": "pA_bar_g", "unit": "bar", "kind": "gauge"},
            "force": {"column": "raw_counts", "unit": "kN", "gain": 0.01, "offset": -1.0},
        },
    }
    df, meta = read_recording(rec, cmap)
    # first data row dropped; ms -> s, mm -> m, bar gauge -> Pa abs, counts*0.01-1 kN -> N
    np.testing.assert_allclose(df["time"], [0.001, 0.002, 0.004], rtol=1e-12)
    np.testing.assert_allclose(df["position"], [0.0105, 0.011, 0.0115], rtol=1e-12)
    np.testing.assert_allclose(df["pressure_a"], [5.1e5 + ATM, 5.2e5 + ATM, 5.3e5 + ATM], rtol=1e-12)
    np.testing.assert_allclose(df["force"], [1000.0, 2000.0, 3000.0], rtol=1e-12)
    assert meta["dropped_rows"] == 1


def test_column_map_toml_file_same_as_dict(tmp_path):
    rec = _write(tmp_path / "a.csv", "t,x\n0,1\n1,2\n")
    map_file = _write(tmp_path / "map.toml", '[columns]\ntime = { column = "t", unit = "s" }\n'
                      'position = { column = "x", unit = "cm" }\n')
    df, _ = read_recording(rec, map_file, required=("time", "position"))
    np.testing.assert_allclose(df["position"], [0.01, 0.02], rtol=1e-12)
    assert load_column_map(map_file).spec("position").unit == "cm"


def test_zillen_fixture_with_shipped_map():
    path = DATA / "zillen" / "O-ring257_7bar_head1000.csv"
    df, meta = read_recording(path, "zillen-friction", required=ZILLEN_NEEDS)
    raw = np.loadtxt(path)  # independent parse of the same bytes
    assert len(df) == 1000 - 15  # the map drops the 15 settling samples
    np.testing.assert_allclose(df["time"], raw[15:, 0] * 1e-3, rtol=1e-12)
    np.testing.assert_allclose(df["position"], raw[15:, 4] * 1e-3, rtol=1e-12)
    np.testing.assert_allclose(df["pressure_a"], raw[15:, 5] * 1e5 + ATM, rtol=1e-12)
    np.testing.assert_allclose(df["force"], raw[15:, 6], rtol=1e-12)
    assert meta["bore"] == pytest.approx(0.0257, rel=1e-12)
    assert "valve_command" not in df.columns  # an absent column stays absent


def test_mat_plain_variables_struct_and_matrix(tmp_path):
    t = np.arange(5) * 0.01
    plain = tmp_path / "plain.mat"
    scipy.io.savemat(plain, {"time": t, "position": t * 2, "valve_command": t * 3})
    df, meta = read_recording(plain)
    np.testing.assert_allclose(df["position"], t * 2, rtol=1e-12)
    assert meta["format"] == "mat"

    struct = tmp_path / "struct.mat"
    scipy.io.savemat(struct, {"rec": {"t_ms": t * 1e3, "x_mm": t * 100, "data": np.column_stack((t, t * 7))}})
    cmap = {"columns": {"time": {"column": "rec.t_ms", "unit": "ms"},
                        "position": {"column": "rec.x_mm", "unit": "mm"},
                        "valve_command": {"column": "rec.data", "index": 1, "unit": "V"}}}
    df, _ = read_recording(struct, cmap)
    np.testing.assert_allclose(df["time"], t, rtol=1e-12)
    np.testing.assert_allclose(df["position"], t * 0.1, rtol=1e-12)
    np.testing.assert_allclose(df["valve_command"], t * 7, rtol=1e-12)


def test_mat_two_structs_refused_unless_a_map_picks_one(tmp_path):
    t = np.arange(5) * 0.01
    path = tmp_path / "two.mat"
    scipy.io.savemat(path, {"run1": {"time": t, "position": t * 2, "valve_command": t}, "run2": {"time": t, "position": t * 3, "valve_command": -t},
                            "info": {"operator": "A. N. Other"}, "description": "two runs"})
    with pytest.raises(InputError, match=r"2 structs hold recording fields \('run1', 'run2'\)"):
        read_recording(path)
    cmap = {"columns": {"time": {"column": "run2.time"}, "position": {"column": "run2.position"},
                        "valve_command": {"column": "run2.valve_command"}}}
    df, _ = read_recording(path, cmap)
    np.testing.assert_allclose(df["position"], t * 3, rtol=1e-12)
    # one struct of recording fields beside a struct and a char variable of other facts: read as before
    one = tmp_path / "one.mat"
    scipy.io.savemat(one, {"run1": {"time": t, "position": t * 2, "valve_command": t}, "info": {"operator": "A"}, "description": "x"})
    df, _ = read_recording(one)
    np.testing.assert_allclose(df["position"], t * 2, rtol=1e-12)


def test_mat_char_in_a_recording_variable_is_named(tmp_path):
    t = np.arange(5) * 0.01
    path = tmp_path / "char.mat"
    scipy.io.savemat(path, {"time": t, "position": "80 mm"})
    with pytest.raises(InputError, match=r"variable 'position' is text \('80 mm'\)"):
        read_recording(path)
    scipy.io.savemat(path, {"rec": {"time": t, "position": "80 mm"}})
    with pytest.raises(InputError, match=r"variable 'rec.position' is text"):
        read_recording(path)


def test_mat_dspace_signal_records(tmp_path):
    t = np.arange(6) * 1e-3
    y = np.zeros((1, 2), dtype=[("Name", "O"), ("Data", "O")])
    y[0, 0] = ("Model Root/Plant/x_mm", t * 1e3)
    y[0, 1] = ("Model Root/Ctrl/u_V", -t)
    path = tmp_path / "dspace.mat"
    scipy.io.savemat(path, {"rec": {"X": {"Data": t}, "Y": y}})
    cmap = {"columns": {"time": {"column": "rec.X.Data"}, "position": {"column": "x_mm", "unit": "mm"},
                        "valve_command": {"column": "u_V"}}}
    df, _ = read_recording(path, cmap)
    np.testing.assert_allclose(df["position"], t, rtol=1e-12)
    np.testing.assert_allclose(df["valve_command"], -t, rtol=1e-12)


def _comtrade_pair(folder: Path, names_units, values, rate=1000.0):
    n = len(values)
    cfg = ["bench,rig1,1999", f"{len(names_units)},{len(names_units)}A,0D"]
    for i, (name, unit) in enumerate(names_units, 1):
        cfg.append(f"{i},{name},,,{unit},0.001,0,0,-99999,99999,1,1,P")
    cfg += ["50", "1", f"{rate:g},{n}", "01/01/2024,00:00:00.000000", "01/01/2024,00:00:00.000000", "ASCII", "1"]
    _write(folder / "rec.cfg", "\n".join(cfg) + "\n")
    dat = [f"{k + 1},{int(round(k * 1e6 / rate))}," + ",".join(str(int(round(v / 0.001))) for v in row)
           for k, row in enumerate(values)]
    _write(folder / "rec.dat", "\n".join(dat) + "\n")
    return folder / "rec.cfg"


def test_comtrade_pair_with_map_and_channel_units(tmp_path):
    values = [(12.0, 5.0, 0.5), (12.5, 5.5, 0.6), (13.0, 6.0, 0.7), (13.5, 6.5, 0.8)]
    cfg = _comtrade_pair(tmp_path, [("x_mm", "mm"), ("pA", "bar"), ("u", "V")], values)
    cmap = {"columns": {"position": {"column": "x_mm"},  # unit from the .cfg channel (mm)
                        "pressure_a": {"column": "pA", "kind": "abs"},
                        "valve_command": {"column": 2}}}
    df, meta = read_recording(cfg, cmap)
    rtol = 1e-12  # read in double precision (the comtrade package's default float32 would give 6e-8)
    np.testing.assert_allclose(df["time"], [0.0, 0.001, 0.002, 0.003], atol=1e-9)  # 1 kHz from the cfg
    np.testing.assert_allclose(df["position"], [0.012, 0.0125, 0.013, 0.0135], rtol=rtol)
    np.testing.assert_allclose(df["pressure_a"], [5e5, 5.5e5, 6e5, 6.5e5], rtol=rtol)
    np.testing.assert_allclose(df["valve_command"], [0.5, 0.6, 0.7, 0.8], rtol=rtol)
    assert meta["format"] == "comtrade" and meta["station_name"] == "bench"
    # the .dat names the same pair
    df2, _ = read_recording(tmp_path / "rec.dat", cmap)
    np.testing.assert_allclose(df2["position"], df["position"])


def test_comtrade_canonical_channel_names(tmp_path):
    cfg = _comtrade_pair(tmp_path, [("position", "mm"), ("valve_command", "V")], [(1.0, 0.1), (2.0, 0.2), (3.0, 0.3)])
    df, _ = read_recording(cfg)
    np.testing.assert_allclose(df["position"], [0.001, 0.002, 0.003], rtol=1e-12)  # double precision


def test_parquet_canonical(tmp_path):
    path = tmp_path / "r.parquet"
    frame = pd.DataFrame({"time": [0.0, 0.5, 1.0], "position": [0.1, 0.2, 0.3], "valve_command": [1.0, 2.0, 3.0]})
    frame.to_parquet(path)
    df, meta = read_recording(path)
    pd.testing.assert_frame_equal(df, frame)
    assert meta["format"] == "parquet"


# ----------------------------------------------------------------------------- bad files
def _error(path, column_map=None, required=("time", "position", "valve_command")) -> str:
    with pytest.raises(InputError) as exc:
        read_recording(path, column_map, required=required)
    return str(exc.value)


def test_bad_no_header(tmp_path):
    msg = _error(_write(tmp_path / "nohead.csv", "0,0.1,0\n0.001,0.1,0\n"))
    assert "nohead.csv" in msg and "line 1" in msg and "no header" in msg


def test_bad_non_numeric_cell_reports_file_line(tmp_path):
    text = "# c1\ntime,position,valve_command\n0,0.1,0\n# c2\n0.001,abc,0\n"
    msg = _error(_write(tmp_path / "cell.csv", text))
    assert "line 5" in msg and "'position'" in msg and "'abc'" in msg  # line 5 as in the file


def test_bad_time_not_increasing(tmp_path):
    text = "time,position,valve_command\n0,0.1,0\n0.002,0.1,0\n0.001,0.1,0\n"
    msg = _error(_write(tmp_path / "back.csv", text))
    assert "line 4" in msg and "not strictly increasing" in msg


def test_bad_nan_run_and_isolated_nan(tmp_path):
    rows = ["time,position,valve_command"] + [f"{i * 0.001},{'' if 3 <= i <= 5 else 0.1},{'nan' if i == 8 else 0}"
                                              for i in range(10)]
    msg = _error(_write(tmp_path / "gaps.csv", "\n".join(rows) + "\n"))
    assert "'position'" in msg and "line 5 to line 7 (3 values)" in msg
    assert "'valve_command'" in msg and "line 10" in msg


def test_bad_unknown_unit(tmp_path):
    rec = _write(tmp_path / "u.csv", "t,x,u\n0,1,0\n1,2,0\n")
    cmap = {"columns": {"time": {"column": "t"}, "position": {"column": "x", "unit": "furlongz"},
                        "valve_command": {"column": "u"}}}
    msg = _error(rec, cmap)
    assert "u.csv" in msg and "'x'" in msg and "furlongz" in msg


def test_bad_missing_required_column(tmp_path):
    msg = _error(_write(tmp_path / "m.csv", "time,position\n0,0.1\n1,0.2\n"))
    assert "m.csv" in msg and "'valve_command'" in msg and "column map" in msg
    # the same file is fine for a caller that does not need the command
    df, _ = read_recording(tmp_path / "m.csv", required=("time", "position"))
    assert len(df) == 2


def test_bad_wrong_field_count(tmp_path):
    msg = _error(_write(tmp_path / "f.csv", "time,position,valve_command\n0,0.1,0\n1,0.2,0,9\n"))
    assert "line 3" in msg


def test_bad_map_entries():
    with pytest.raises(InputError, match="kind"):
        load_column_map({"columns": {"pressure_a": {"column": "p", "unit": "bar"}}})
    with pytest.raises(InputError, match="did you mean 'delimiter'"):
        load_column_map({"delimter": ",", "columns": {"time": {"column": "t"}}})
    with pytest.raises(InputError, match="0-based index"):
        load_column_map({"header": False, "columns": {"time": {"column": "t"}}})
    with pytest.raises(InputError, match="not a canonical column"):
        load_column_map({"columns": {"positon": {"column": "x"}}})
    with pytest.raises(InputError, match="neither a file nor a shipped map"):
        load_column_map("zillen-fricton")


def test_bad_files_and_pairs(tmp_path):
    assert "not found" in _error(tmp_path / "nope.csv")
    assert "unknown recording format" in _error(_write(tmp_path / "r.xlsx", "x"))
    assert "only blank" in _error(_write(tmp_path / "empty.csv", "# nothing\n\n"))
    _write(tmp_path / "lonely.cfg", "x\n")
    assert "both NAME.cfg and NAME.dat" in _error(tmp_path / "lonely.cfg")
    assert "not a readable MATLAB" in _error(_write(tmp_path / "fake.mat", "not a mat file"))


def test_bad_sidecar_pressure_without_abs_or_gauge(tmp_path):
    rec = _write(tmp_path / "s.csv", CANONICAL)
    _write(tmp_path / "s.toml", '[conditions]\nsupply_pressure = "8 bar"\n')
    msg = _error(rec)
    assert "s.toml" in msg and "supply_pressure" in msg and "abs" in msg


def test_bad_mat_variable_missing_suggests(tmp_path):
    path = tmp_path / "v.mat"
    scipy.io.savemat(path, {"x_mm": np.arange(3.0), "t": np.arange(3.0)})
    cmap = {"columns": {"time": {"column": "t"}, "position": {"column": "x_m", "unit": "mm"}}}
    msg = _error(path, cmap, required=("time", "position"))
    assert "v.mat" in msg and "did you mean 'x_mm'" in msg

"""COMTRADE (IEEE C37.111-1999/2013): every edition, data type and form a plant-A run is written in reads
back to within the file's own resolution, on primary values, on a uniform double-precision time axis,
and replays as a perfect fit; the bad files are refused naming their cause."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from compliance.cli import build_parser, main
from compliance.cli.simulate import build_scenario, sidecar_text
from compliance.errors import InputError
from compliance.recordings.comtrade_write import comtrade_bytes
from compliance.recordings.reader import read_recording
from compliance.validation.resampling import is_uniform

SIGNALS = ("position", "reference", "valve_command", "pressure_a", "pressure_b", "supply_pressure")
ARGV = ["simulate", "plant-a", "--x0", "136mm", "--steps", "-2%@0.3s", "--duration", "1"]
STEP_AT = 0.3  # [s] the set-point step of ARGV: the trigger of the files written from it


@pytest.fixture(scope="module")
def run():
    """One small plant-A run (1 s, 1 kHz, a 2 % closing step) exactly as ``govcheck simulate ARGV`` makes it."""
    from compliance.model.config import load_plant
    from compliance.plants import simulate

    args = build_parser().parse_args(ARGV + ["-o", "unused.csv"])
    cfg = load_plant("plant-a")
    scenario = build_scenario(cfg, args)
    return cfg, scenario, simulate(cfg, scenario)


# (edition, data type, single file, time offset [s], secondary-side channels with their primary:secondary ratio)
VARIANTS = {
    "2013-binary32": ("2013", "BINARY32", False, 0.0, None),
    "2013-float32": ("2013", "FLOAT32", False, 0.0, None),
    "2013-binary16": ("2013", "BINARY", False, 0.0, None),
    "2013-ascii-cff": ("2013", "ASCII", True, 0.0, None),
    "2013-binary32-cff": ("2013", "BINARY32", True, 0.0, None),
    "1999-ascii": ("1999", "ASCII", False, 0.0, None),
    "1999-binary16": ("1999", "BINARY", False, 0.0, None),
    "2013-secondary-ratio-2": ("2013", "BINARY", False, 0.0, {"pressure_a": (2.0, 1.0), "pressure_b": (2.0, 1.0)}),
    "2013-offset-3600s": ("2013", "BINARY32", False, 3600.0, None),
}


def _write(folder: Path, run, variant: str) -> Path:
    cfg, scenario, df = run
    revision, file_type, single, offset, ratios = VARIANTS[variant]
    frame = df.copy()
    frame["time"] += offset
    files = comtrade_bytes(frame, station="plant-a bench", revision=revision, file_type=file_type,
                           single_file=single, trigger_time=offset + STEP_AT, ratios=ratios)
    for suffix, data in files.items():
        (folder / f"rec{suffix}").write_bytes(data)
    (folder / "rec.toml").write_text(sidecar_text(cfg, scenario, "plant-a"), encoding="utf-8")
    return folder / ("rec.cff" if single else "rec.cfg")


def _package_read(path: Path, **kw):
    import comtrade

    return comtrade.load(str(path), ignore_warnings=True, use_numpy_arrays=True, **kw)


@pytest.mark.parametrize("variant", VARIANTS)
def test_reads_back_within_the_files_resolution_on_primary_values(tmp_path, run, variant):
    _, _, df = run
    offset, ratios = VARIANTS[variant][3], VARIANTS[variant][4] or {}
    path = _write(tmp_path, run, variant)
    frame, meta = read_recording(path)
    t = frame["time"].to_numpy()
    np.testing.assert_allclose(t, df["time"].to_numpy() + offset, rtol=0, atol=1e-9)  # double precision, even at 3600 s
    assert is_uniform(t, 1e-3, rtol=1e-6)
    for name in SIGNALS:
        res = meta["channels"][name]["resolution"]
        err = np.max(np.abs(frame[name].to_numpy() - df[name].to_numpy()))
        # a value is rounded to the nearest step of the file (half a resolution), plus float64 rounding of a*x+b
        assert err <= 0.5 * res * (1 + 1e-6) + 1e-12 * abs(df[name]).max(), (name, err, res)
        assert res < 1e-4 * max(np.ptp(df[name].to_numpy()), abs(df[name]).max())  # a resolution, not a range
    # trigger_time is measured from the first sample (C37.111: the first stamp dates the first sample), so on the
    # file's time axis, which starts at the offset here, the trigger is at the first sample's time plus it
    assert meta["trigger_time"] == pytest.approx(STEP_AT, abs=1e-6)
    assert t[0] + meta["trigger_time"] == pytest.approx(offset + STEP_AT, abs=1e-6)
    assert meta["comtrade"]["revision"] == VARIANTS[variant][0]
    assert meta["comtrade"]["form"] == ("cff" if VARIANTS[variant][2] else "pair")
    # the comtrade package, an independent reader, sees the same samples: secondary ones where the file says S
    rec = _package_read(path, use_double_precision=True)
    assert rec.trigger_time == pytest.approx(meta["trigger_time"], abs=1e-6)  # the same reading as the comtrade package
    for name in ("position", "pressure_a"):
        raw = np.asarray(rec.analog[rec.analog_channel_ids.index(name)])
        ratio = ratios.get(name, (1.0, 1.0))
        np.testing.assert_allclose(raw * ratio[0] / ratio[1], frame[name].to_numpy(), rtol=1e-12)


@pytest.mark.parametrize("variant", VARIANTS)
def test_replays_against_plant_a_as_a_perfect_fit(tmp_path, run, variant):
    from compliance.validation.validate import validate

    cfg, _, _ = run
    frame, meta = read_recording(_write(tmp_path, run, variant))
    result = validate(cfg, frame, meta)
    assert result["summary"]["pass"]
    for mode in ("closed_loop", "plant_only"):
        out = result["modes"][mode]
        assert not out["located_windows"], (mode, out["located_windows"][:1])
        for name in ("position", "pressure_a", "pressure_b"):
            assert out["fits"][name]["fit_percent"] > 99.99, (mode, name, out["fits"][name])


def test_float32_time_is_what_breaks_a_one_hour_offset(tmp_path, run):
    """Why double precision: float32 time at t = 3600 s has 0.24 ms steps, so a 1 ms file looks non-uniform."""
    path = _write(tmp_path, run, "2013-offset-3600s")
    single = np.asarray(_package_read(path).time)  # the comtrade package's default: float32
    assert single.dtype == np.float32 and not is_uniform(single.astype(float), 1e-3)
    assert is_uniform(read_recording(path)[0]["time"].to_numpy(), 1e-3, rtol=1e-6)


def test_a_factor_is_the_resolution_and_a_sidecar_resolution_can_only_coarsen_it(tmp_path, run):
    path = _write(tmp_path, run, "2013-binary16")
    _, meta = read_recording(path)
    res = meta["channels"]["position"]["resolution"]
    a = float(next(line for line in path.read_text().splitlines() if ",position," in line).split(",")[5])
    assert res == pytest.approx(a, rel=1e-12)
    side = tmp_path / "rec.toml"
    side.write_text(side.read_text() + '\n[channels.position]\nresolution = "0.01 mm"\n[channels.pressure_a]\n'
                    'resolution = 1e-9\n', encoding="utf-8")
    _, meta = read_recording(path)
    assert meta["channels"]["position"]["resolution"] == pytest.approx(1e-5)  # the sensor is coarser than the file
    assert meta["channels"]["pressure_a"]["resolution"] > 1e-9  # the file is coarser than the sidecar claims


def test_ascii_numbers_with_decimals_resolve_their_last_decimal_on_the_primary_side(tmp_path):
    """A 2013 ASCII file written with decimals: resolution = a x the last decimal place x primary/secondary."""
    cfg = ["bench,rig1,2013", "2,2A,0D", "1,position,,,mm,1,0,0,-99999,99999,1,1,P",
           "2,pressure_a,,,bar,0.5,0,0,-99999,99999,10,1,S",
           "0", "1", "1000,3", "01/01/2024,00:00:00.000000", "01/01/2024,00:00:00.250000", "ASCII", "1", "0,0", "F,0"]
    (tmp_path / "r.cfg").write_text("\r\n".join(cfg) + "\r\n", encoding="ascii")
    (tmp_path / "r.dat").write_text("1,0,12.125,1.5\r\n2,1000,12.25,1.25\r\n3,2000,12.5,1.0\r\n", encoding="ascii")
    cmap = {"columns": {"position": {"column": "position"}, "pressure_a": {"column": "pressure_a", "kind": "abs"}}}
    frame, meta = read_recording(tmp_path / "r.cfg", cmap, required=("position", "pressure_a"))
    np.testing.assert_allclose(frame["position"], [0.012125, 0.01225, 0.0125], rtol=1e-12)
    np.testing.assert_allclose(frame["pressure_a"], [7.5e5, 6.25e5, 5e5], rtol=1e-12)  # 0.5 x raw bar x 10 / 1
    assert meta["channels"]["position"]["resolution"] == pytest.approx(1e-6)  # 1 x 0.001 mm
    assert meta["channels"]["pressure_a"]["resolution"] == pytest.approx(0.5 * 0.01 * 10 * 1e5)  # a x 0.01 bar x 10
    assert meta["trigger_time"] == pytest.approx(0.25)


@pytest.mark.parametrize("revision,file_type", [("1999", "ASCII"), ("2013", "BINARY32"), ("2013", "BINARY")])
def test_a_missing_sample_is_written_as_the_standards_missing_value_and_refused_on_reading(tmp_path, run, revision,
                                                                                           file_type):
    _, _, df = run
    frame = df.copy()
    frame.loc[2, "position"] = np.nan
    for suffix, data in comtrade_bytes(frame, station="s", revision=revision, file_type=file_type).items():
        (tmp_path / f"r{suffix}").write_bytes(data)
    assert np.isnan(np.asarray(_package_read(tmp_path / "r.cfg", use_double_precision=True).analog[0])[2])
    with pytest.raises(InputError, match=r"column 'position' has NaN/empty/infinite values at sample 3"):
        read_recording(tmp_path / "r.cfg")


THIRD_PARTY = Path(__file__).resolve().parents[1] / "data" / "comtrade"  # python-comtrade's samples (tests/data/README.md)


@pytest.mark.parametrize("name", ["sample_float32.cff", "sample_ascii.cff", "sample_bin.cfg"])
def test_files_written_by_other_tools_read_as_the_comtrade_package_reads_them(name):
    """2013 FLOAT32 and ASCII .cff with status channels, 1999 16-bit BINARY: same samples, same time axis.

    The ASCII one is a relay's secondary-side record (P/S = s, CT ratio 933:1): govcheck gives
    the primary currents, 933 x what the package gives.
    """
    from compliance.recordings.comtrade import read_comtrade

    src = read_comtrade(THIRD_PARTY / name, None)
    rec = _package_read(THIRD_PARTY / name, use_double_precision=True)
    np.testing.assert_array_equal(src.time, np.asarray(rec.time))
    for k, ch in enumerate(rec.cfg.analog_channels):
        spec = type("Spec", (), {"column": k, "name": ch.name})()
        values, unit = src.get(spec)
        ratio = ch.primary / ch.secondary if ch.pors.strip().upper() == "S" else 1.0
        np.testing.assert_allclose(values, ratio * np.asarray(rec.analog[k]), rtol=1e-15)
        assert unit == (ch.uu.strip() or None)
        if rec.ft.upper() == "BINARY":
            assert src.facts(spec)["resolution"] == pytest.approx(abs(ch.a))
    if name == "sample_ascii.cff":
        assert rec.cfg.analog_channels[0].pors.strip() == "s" and src.facts(spec)["resolution"] == pytest.approx(
            0.1138916015625 * 933)  # a x the CT ratio: the integer samples' step in primary amperes


# ----------------------------------------------------------------------------- bad files
def _edit_cfg(path: Path, old: str, new: str) -> None:
    text = path.read_bytes().decode("ascii")
    assert old in text
    path.write_bytes(text.replace(old, new, 1).encode("ascii"))


@pytest.mark.parametrize("variant", ["2013-binary32", "1999-ascii"])
def test_a_dat_shorter_than_the_cfg_declares_is_refused(tmp_path, run, variant):
    path = _write(tmp_path, run, variant)
    dat = tmp_path / "rec.dat"
    data = dat.read_bytes()
    dat.write_bytes(data[: len(data) * 2 // 3])
    with pytest.raises(InputError, match=r"rec\.dat: the \.dat is shorter than the \.cfg declares.*1001 samples"):
        read_recording(path)


def test_binary_data_declared_ascii_is_refused(tmp_path, run):
    path = _write(tmp_path, run, "2013-binary32")
    _edit_cfg(path, "\r\nBINARY32\r\n", "\r\nASCII\r\n")
    with pytest.raises(InputError, match=r"rec\.dat: binary data declared ASCII: byte 0x.. at offset \d+"):
        read_recording(path)


@pytest.mark.parametrize("fields,message", [
    (",0,0,S", r"analog channel 4 'pressure_a': P/S = S .* ratio primary:secondary = 0:0"),  # S without a usable ratio
    (",2.0,1.0,", r"'pressure_a': P/S flag '\(empty\)' is neither P nor S.*2:1.*cannot be told"),  # ambiguous
])
def test_primary_secondary_that_cannot_be_resolved_is_refused(tmp_path, run, fields, message):
    path = _write(tmp_path, run, "2013-secondary-ratio-2")
    _edit_cfg(path, ",2.0,1.0,S", fields)
    with pytest.raises(InputError, match=message):
        read_recording(path)


def test_a_cut_cff_is_refused(tmp_path, run):
    path = _write(tmp_path, run, "2013-binary32-cff")
    data = path.read_bytes()
    path.write_bytes(data[:-100])
    with pytest.raises(InputError, match=r"rec\.cff: DAT section: the header declares \d+ bytes but the file ends"):
        read_recording(path)
    path.write_bytes(data[: data.index(b"--- file type: DAT")])
    with pytest.raises(InputError, match=r"rec\.cff: a \.cff needs a '--- file type: DAT ---' section"):
        read_recording(path)


def test_cff_data_section_is_headed_binary_and_the_type_word_is_read_too(tmp_path, run):
    """C37.111-2013 heads a .cff's binary data 'DAT BINARY: <bytes>' whatever the binary type (the CFG's ft line
    says BINARY32); govcheck writes that, the comtrade package reads it, and a device's 'DAT BINARY32:' is read too."""
    path = _write(tmp_path, run, "2013-binary32-cff")
    data = path.read_bytes()
    head = data[data.index(b"--- file type: DAT"):].split(b"\r\n", 1)[0]
    n = len(data) - data.index(head) - len(head) - 2
    assert head == f"--- file type: DAT BINARY: {n} ---".encode()
    assert _package_read(path, use_double_precision=True).ft == "BINARY32"
    frame, _ = read_recording(path)
    path.write_bytes(data.replace(b"DAT BINARY: ", b"DAT BINARY32: "))
    again, _ = read_recording(path)
    np.testing.assert_array_equal(frame["position"].to_numpy(), again["position"].to_numpy())


# ----------------------------------------------------------------------------- govcheck simulate -o run.cfg
@pytest.mark.parametrize("suffix", [".cfg", ".cff"])
def test_simulate_writes_comtrade_that_round_trips(tmp_path, run, suffix, capsys):
    _, _, df = run
    out = tmp_path / f"run{suffix}"
    assert main(ARGV + ["-o", str(out)]) == 0
    expected = {".cfg": ["run.cfg", "run.dat", "run.toml"], ".cff": ["run.cff", "run.toml"]}[suffix]
    assert sorted(p.name for p in tmp_path.iterdir()) == expected
    first = out.read_bytes().split(b"\n", 2)
    assert first[0 if suffix == ".cfg" else 1].strip() == b"plant-a,govcheck,2013"
    frame, meta = read_recording(out)
    rec = _package_read(out, use_double_precision=True)
    assert rec.ft == "BINARY32" and rec.rev_year == "2013"
    np.testing.assert_allclose(np.asarray(rec.time), df["time"], rtol=0, atol=1e-12)
    for name in SIGNALS:
        got = np.asarray(rec.analog[rec.analog_channel_ids.index(name)])
        tol = 0.5 * meta["channels"][name]["resolution"] * (1 + 1e-6) + 1e-12 * abs(df[name]).max()
        assert np.max(np.abs(got - df[name])) <= tol, name
        np.testing.assert_allclose(frame[name], got, rtol=1e-15)
    assert meta["trigger_time"] == pytest.approx(STEP_AT)
    if suffix == ".cfg":
        capsys.readouterr()
        assert main(["validate", str(out), "--mode", "plant_only"]) == 0
        assert "result: PASS" in capsys.readouterr().out


def test_simulate_refuses_a_read_only_dat_before_any_work(tmp_path, capsys):
    dat = tmp_path / "run.dat"
    dat.write_bytes(b"old")
    dat.chmod(0o444)
    assert main(ARGV + ["-o", str(tmp_path / "run.cfg")]) == 2
    assert "run.dat: the file exists and is read-only" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.dat"] and dat.read_bytes() == b"old"

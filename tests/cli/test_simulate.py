"""simulate writes its sidecar (simulate -> validate round-trips), an SVG when asked for one, nothing on failure."""

from __future__ import annotations

import stat
import tomllib

from compliance.cli import main


def test_simulate_validate_round_trip_with_sidecar(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "models").mkdir()
    assert main(["simulate", "plant-a", "--x0", "136 mm", "--load", "11.4 kN", "--steps", "2%@0.5s",
                 "--duration", "1.5", "--noise", "-o", "run.csv", "--plot", "run.svg"]) == 0
    side = tomllib.loads((tmp_path / "run.toml").read_text())
    assert side["plant"] == "plant-a"
    assert side["conditions"]["load_force"] == 11400.0 and side["conditions"]["initial_position"] == 0.136
    assert side["controller"]["kp"] == 280.0 and side["controller"]["sample_time"] == 0.001
    assert (tmp_path / "run.svg").read_bytes().lstrip().startswith(b"<?xml")  # SVG bytes for .svg, not PNG
    modes = {stat.S_IMODE((tmp_path / n).stat().st_mode) for n in ("run.csv", "run.toml", "run.svg")}
    assert len(modes) == 1  # one permission for every file govcheck writes
    capsys.readouterr()
    # the run's own conditions make the replay fit: no "non-physical ... reduce simulation.step"
    assert main(["validate", "run.csv", "--mode", "closed_loop", "--json", "v.json"]) == 0
    out = capsys.readouterr().out
    assert "conditions: x0 136.00 mm, load 11400 N" in out


def test_simulate_plant_file_path_in_sidecar_is_relative_to_the_recording(tmp_path, monkeypatch):
    from pathlib import Path

    src = Path(__file__).resolve().parents[2] / "models" / "plant-a.toml"
    (tmp_path / "models").mkdir()
    (tmp_path / "models" / "plant-a.toml").write_text(src.read_text())
    (tmp_path / "runs").mkdir()
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", "models/plant-a.toml", "--duration", "0.2", "-o", "runs/r.csv"]) == 0
    assert tomllib.loads((tmp_path / "runs" / "r.toml").read_text())["plant"] == "../models/plant-a.toml"
    from compliance.cli.common import sidecar_plant

    assert Path(sidecar_plant({"plant": "../models/plant-a.toml"}, "runs/r.csv")).resolve() == (tmp_path / "models" / "plant-a.toml").resolve()


def test_failed_plot_leaves_the_old_csv(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "run.csv").write_text("old\n")
    assert main(["simulate", "plant-a", "-o", "run.csv", "--plot", "nodir/p.png"]) == 2
    assert (tmp_path / "run.csv").read_text() == "old\n" and not (tmp_path / "run.toml").exists()

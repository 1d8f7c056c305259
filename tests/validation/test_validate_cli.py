"""End to end: ``govcheck validate`` through compliance.cli.main."""

from __future__ import annotations

import importlib
import json

import pytest

from compliance.cli import main
from compliance.model.config import load_plant
from compliance.recordings.synth import PRACTICE_NOISE, synthesise, write_recording


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    d = tmp_path_factory.mktemp("val")
    plant = load_plant("plant-a")
    clean, meta = synthesise(plant, x0=0.06, load=7000.0, kd=6.0, noise=None, duration=12.0, profile_kind="steps")
    noisy, nmeta = synthesise(plant, x0=0.06, load=7000.0, kd=6.0, noise=PRACTICE_NOISE, seed=9, duration=12.0, profile_kind="steps")
    write_recording(clean, meta, d / "clean.csv")
    write_recording(noisy, nmeta, d / "noisy.csv.gz")
    no_ref = clean.drop(columns=["reference"])
    write_recording(no_ref, meta, d / "noref.csv")
    return d


def test_validate_self_recording_passes_and_writes_json(recordings, tmp_path, capsys):
    out = tmp_path / "val.json"
    code = main(["validate", str(recordings / "clean.csv"), "--plant", "plant-a", "--json", str(out)])
    text = capsys.readouterr().out
    assert code == 0, text
    assert "closed-loop replay" in text and "plant-only replay" in text and "fit %" in text
    res = json.loads(out.read_text())
    assert res["schema"] == "govcheck.validation/1"
    assert set(res["modes"]) == {"closed_loop", "plant_only"}
    cl, po = res["modes"]["closed_loop"], res["modes"]["plant_only"]
    for s in ("position", "pressure_a", "pressure_b"):
        assert cl["fits"][s]["fit_percent"] > 99.9 and po["fits"][s]["fit_percent"] > 99.9  # model vs itself
    assert "valve_command" in cl["fits"] and "valve_command" not in po["fits"]  # plant-only input is not a fit
    assert po["overlays"]["valve_command"]["role"] == "input"
    assert cl["located_windows"] == [] and po["located_windows"] == []
    for mode in res["modes"].values():
        for s, ov in mode["overlays"].items():
            assert len(ov["time"]) == len(ov["recorded"]) == len(ov["simulated"]) <= 3000
        for s, r in mode["residuals"].items():
            assert len(r["time"]) <= 3000 and r["threshold_on"] > r["threshold_off"] > 0
    assert [w["kind"] for w in res["windows"]][:3] == ["steady", "transient", "steady"]
    assert res["conditions"]["controller"]["kd"] == 6.0 and res["conditions"]["load_force"] == 7000.0


def test_limits_decide_the_exit_code(recordings, capsys):
    rec = str(recordings / "noisy.csv.gz")
    # a zero limit on the position's steady MXE cannot hold with 20 um sensor noise in the recording
    code = main(["validate", rec, "--plant", "plant-a", "--mode", "plant_only", "--setting", "limits.position.steady.max_error=0", "--setting", "metrics.error_filter_cutoff=0"])
    assert code == 1
    assert "FAIL" in capsys.readouterr().out
    assert main(["validate", rec, "--plant", "plant-a", "--mode", "plant-only"]) == 0


def test_plant_named_by_the_sidecar(recordings, capsys):
    assert main(["validate", str(recordings / "clean.csv"), "--mode", "closed_loop"]) == 0
    assert "model plant-a" in capsys.readouterr().out


@pytest.mark.parametrize(
    "args, message",
    [
        (["missing.csv", "--plant", "plant-a"], "not found"),
        (["{d}/clean.csv", "--plant", "plant-a", "--mode", "open_loop"], "--mode"),
        (["{d}/clean.csv", "--plant", "plant-z"], "plant-z"),
        (["{d}/clean.csv", "--plant", "plant-a", "--setting", "locate.k_onn=3"], "k_on"),
        (["{d}/clean.csv", "--plant", "plant-a", "--setting", "limits.position.steady.max_error=-1"], "max_error"),
        (["{d}/clean.csv", "--plant", "plant-a", "--param", "friction.stiffnes=1e6"], "friction"),
        (["{d}/clean.csv", "--plant", "plant-a", "--param", "friction.bristle_stiffness=big"], "not a number"),
        (["{d}/noref.csv", "--plant", "plant-a", "--mode", "closed_loop"], "reference"),
        (["{d}/clean.csv", "--plant", "plant-a", "--settings", "{d}/nope.toml"], "settings file not found"),
        (["{d}/clean.csv", "--plant", "plant-a", "--pdf", "x.pdf"], "--report"),
        (["{d}/clean.csv", "--plant", "plant-a", "--noise", "loud"], "noise"),
    ],
)
def test_bad_input_exits_2(recordings, capsys, args, message):
    argv = ["validate"] + [a.format(d=recordings) for a in args]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("govcheck validate: error:") and message in err
    assert "Traceback" not in err


def test_missing_reference_skips_closed_loop_with_a_warning(recordings, capsys):
    assert main(["validate", str(recordings / "noref.csv"), "--plant", "plant-a"]) == 0
    out = capsys.readouterr().out
    assert "closed_loop replay skipped" in out and "plant-only replay" in out


def test_report_option(recordings, tmp_path, capsys):
    html = tmp_path / "val.html"
    code = main(["validate", str(recordings / "clean.csv"), "--plant", "plant-a", "--report", str(html)])
    try:
        render = importlib.import_module("compliance.report.render")
        available = hasattr(render, "render_validation_report")
    except ImportError:
        available = False
    if available:
        assert code == 0 and html.is_file() and html.stat().st_size > 0
    else:
        assert code == 2
        assert "report rendering not available yet" in capsys.readouterr().err

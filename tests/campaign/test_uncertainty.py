"""Uncertainty bands: local one-at-a-time sensitivities against a brute-force Monte Carlo (issue 22).

Small case: plant A's closing stroke at the rated 12 kN, with two ranged parameters (the valve
conductance, +/-10 %, and the static friction, +/-20 %). The closing time through a meter-out
throttle responds smoothly to both, so the interval sum of the one-sided swings must contain the
spread of a Latin-hypercube Monte Carlo over the same ranges and be not much wider than it (16
plants reach most of the corners of a 2-D box).
"""

import copy
from pathlib import Path
import dataclasses
from types import MappingProxyType

import pytest

from compliance.campaign.run import run_campaign
from compliance.model.config import load_plant
from compliance.requirements.loading import load_requirements
from compliance.sweep.tolerance.uncertainty_mc import monte_carlo_bands

REQ = """
schema = "govcheck-requirements/1"
name = "closing"
[operating_points.rated]
initial_position = "80 %stroke"
load = "12 kN"
flow_control = true
[procedures.close]
kind = "full_stroke"
directions = ["closing"]
[requirements.TCLOSE]
title = "closing time"
clause = "clause unknown"
metric = "closing_time"
comparator = ">="
limit = "3.47 s"
procedures = ["close"]
operating_points = ["rated"]
"""


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    cfg = load_plant("plant-a")
    keep = {k: v for k, v in cfg.assumptions.items() if k in ("valve.sonic_conductance", "friction.static_force")}
    cfg = dataclasses.replace(cfg, assumptions=MappingProxyType(keep))
    p = tmp_path_factory.mktemp("req") / "closing.toml"
    p.write_text(REQ)
    reqset = load_requirements(p)
    return cfg, reqset, run_campaign(cfg, reqset, workers=1, progress=False, uncertainty="local")


def test_local_band_contains_the_monte_carlo_spread(case):
    cfg, reqset, local = case
    e = local["requirements"][0]
    band = e["band"]
    assert band["method"] == "local" and set(band["swings"]) == {"valve.sonic_conductance", "friction.static_force"}
    v0 = e["worst"]["value"]
    assert band["low"] < v0 < band["high"]
    # a larger valve conductance fills and exhausts faster: the closing time falls
    assert band["swings"]["valve.sonic_conductance"][0] < 0
    mc = copy.deepcopy(local)
    for r in mc["requirements"]:
        r["status"] = r["worst"]["status"] = r["rows"][0]["status"] = "pass" if r["worst"]["value"] >= 3.47 else "fail"
    info = monte_carlo_bands(cfg, reqset, mc["requirements"], 16, workers=1)
    assert info["judged"] == 16
    m = mc["requirements"][0]["band"]
    width = band["high"] - band["low"]
    assert m["low"] >= band["low"] - 0.15 * width and m["high"] <= band["high"] + 0.15 * width
    assert (m["high"] - m["low"]) >= 0.5 * width


def test_a_band_across_the_limit_is_uncertain_and_names_its_parameters(case):
    cfg, reqset, local = case
    e = local["requirements"][0]
    # 3.47 s lies inside the band of the ~3.45 s closing time: the verdict cannot be decided
    assert e["band"]["low"] < 3.47 < e["band"]["high"]
    assert e["status"] == "uncertain" and local["summary"]["uncertain"] == ["TCLOSE"]
    assert e["band"]["deciding"] and set(e["band"]["deciding"]) <= {"valve.sonic_conductance", "friction.static_force"}
    assert local["summary"]["status"] == "incomplete"
    assert [a["parameter"] for a in local["uncertainty"]["top_assumptions"]][0] in e["band"]["deciding"]


def test_check_uncertainty_option_runs_a_monte_carlo(tmp_path, capsys):
    from compliance.cli import main

    req = tmp_path / "closing.toml"
    req.write_text(REQ)
    out = tmp_path / "r.json"
    assert main(["check", "plant-a", "-r", str(req), "--uncertainty", "1", "--json", str(out), "-q"]) == 2
    assert "--uncertainty 1" in capsys.readouterr().err and not out.exists()
    code = main(["check", "plant-a", "-r", str(req), "--uncertainty", "4", "--jobs", "1", "--json", str(out), "-q"])
    import json

    r = json.loads(out.read_text())
    assert code in (0, 1) and r["uncertainty"]["method"] == "monte_carlo" and r["uncertainty"]["judged"] == 4
    band = r["requirements"][0]["band"]
    assert band["method"].startswith("monte carlo") and band["low"] <= r["requirements"][0]["worst"]["value"] <= band["high"]
    assert r["summary"]["top_assumptions"]


def test_uncertainty_needs_a_plant_with_ranges(tmp_path, capsys):
    from compliance.cli import main

    req = tmp_path / "closing.toml"
    req.write_text(REQ)
    out = tmp_path / "r.json"
    plant = Path(__file__).resolve().parents[2] / "models" / "plant-a-calibrated.toml"
    assert main(["check", str(plant), "-r", str(req), "--uncertainty", "4", "--json", str(out), "-q"]) == 2
    assert "gives no parameter a range" in capsys.readouterr().err and not out.exists()

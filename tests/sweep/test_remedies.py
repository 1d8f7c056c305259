"""Remedies: nothing to change for a passing configuration; a found remedy is verified by its own campaign."""

import json

import pytest

from compliance.campaign.run import run_campaign
from compliance.cli import main
from compliance.model.config import load_plant
from compliance.requirements.loading import load_requirements
from compliance.sweep.check_remedies import remedies_for_check

from tests.sweep.conftest import SMALL_TC, sweep_text


@pytest.fixture(scope="module")
def reqset():
    return load_requirements(SMALL_TC)


def test_passing_configuration_has_no_remedy(write_sweep, reqset):
    cfg = load_plant("plant-a").replace(params={"controller.kp": 400.0})  # TC 0.12 s: inside 0.10-0.25 s
    rem = remedies_for_check(cfg, reqset, str(write_sweep(sweep_text())), workers=1, progress=False)
    assert rem["status"] == "already_passes"
    assert rem["failed"] == [] and rem["sensitivities"] == [] and rem["remedy"] is None and rem["evaluated"] == 1


def test_remedy_found_is_verified_by_its_own_campaign(write_sweep, reqset):
    cfg = load_plant("plant-a")  # TC 0.27 s at mid stroke: static friction delays the 5 % step
    rem = remedies_for_check(cfg, reqset, str(write_sweep(sweep_text())), workers=2, progress=False)
    assert rem["status"] == "found" and rem["failed"] == ["TC"]
    # the time constant falls as kp rises: its margin's sensitivity to kp is positive and the largest
    sens = rem["sensitivities"][0]
    assert sens["requirement"] == "TC" and sens["by_parameter"][0]["path"] == "controller.kp"
    assert sens["by_parameter"][0]["delta_margin_pct"] > 0
    r = rem["remedy"]
    assert r["verified"]["status"] == "pass"
    assert r["values"]["controller.kp"] > 280.0
    # independent check: our own campaign of the changed configuration passes
    paths = {"controller.kp": None, "controller.kd": None}
    changed = cfg.replace(params={k: v for k, v in r["values"].items() if k in paths})
    res = run_campaign(changed, reqset, workers=1, progress=False)
    assert res["summary"]["status"] == "pass"


def test_no_remedy_in_the_space_names_the_binding_requirement(write_sweep, reqset):
    # below the configured 280 V/m the proportional gain builds the breakaway force later:
    # the time constant only grows (0.31 s at 250 V/m, 0.48 s at 200 V/m)
    adjust = '[adjust."controller.kp"]\nrange = ["150 V/m", "260 V/m"]\n'
    rem = remedies_for_check(load_plant("plant-a"), reqset, str(write_sweep(sweep_text(adjust=adjust))),
                             workers=1, progress=False, iterations=1, catalogue=None)
    assert rem["status"] == "none_found" and rem["remedy"] is None
    assert rem["closest"]["binding"] == "TC" and rem["closest"]["binding_margin_pct"] < 0
    assert "not a proof" in rem["note"]
    # the summary of this search: the judged count stated as such, kp in V/m with its unit, no raw floats
    import re

    from compliance.sweep.summary_text import summary_markdown

    summary = {"name": "s", "title": "t", "sweep_file": "s.toml", "method": "optimise", "seed": 1, "candidates": 8,
               "counts": {"fail": 8}, "passing": 0, "executor": None, "wall": 1.0,
               "pareto": {"requirements": [], "candidates": []}, "best": None, "parameters": [], "remedies": rem}
    md = summary_markdown(summary)
    assert f"judged {rem['evaluated']} candidate settings in all" in md and "0 of the 8 drawn candidates pass" in md
    step = rem["sensitivities"][0]["by_parameter"][0]["step"]  # 10 % of the 150-260 V/m range: 11 V/m
    assert f"controller.kp +{step:.4g} V/m: " in md, md
    assert not re.search(r"\d[eE][+-]\d", md) and "seed" not in md


def test_check_remedies_cli_writes_the_section(tmp_path, capsys):
    out = tmp_path / "r.json"
    code = main(["check", "plant-a", "-r", str(SMALL_TC), "--remedies", "--json", str(out), "-j", "2"])
    assert code == 1  # the configuration as given still fails; the remedy is advice
    text = capsys.readouterr().out
    assert "What would make it pass" in text
    rem = json.loads(out.read_text())["remedies"]
    assert rem["status"] == "found" and rem["remedy"]["verified"]["status"] == "pass"

"""``compliance.check``: one library call, steps public, the requirement set vetted once before any simulation."""

import pytest

import compliance
from compliance.errors import InputError
from compliance.model.config import load_plant
from compliance.pipeline import chain as pipeline
from compliance.requirements.loading import load_requirements
from tests.requirements.test_consistency import STRICT


@pytest.fixture()
def strict(tmp_path):
    p = tmp_path / "strict.toml"
    p.write_text(STRICT)
    return p


def _no_simulation(*a, **k):
    raise AssertionError("a refused check must not simulate")


def test_a_library_call_on_a_conflicting_set_is_refused_before_simulating(strict, monkeypatch):
    from compliance.campaign import run as campaign_run

    monkeypatch.setattr(campaign_run, "execute", _no_simulation)
    with pytest.raises(InputError, match="contradicts itself.*40.5 mm/s"):
        compliance.check("plant-a", strict)
    with pytest.raises(InputError, match="contradicts itself"):  # the campaign alone refuses it too
        campaign_run.run_campaign(load_plant("plant-a"), load_requirements(strict))
    prepared = pipeline.Check.of("plant-a", strict, allow_conflicts=True)  # judged anyway when the caller says so
    assert any(f["kind"] == "conflict" and f["mandatory"] for f in prepared.vetting.findings)


def test_loosening_and_conflicts_are_checked_once(monkeypatch, tmp_path):
    from compliance.requirements import vetting

    calls = {"tightening": 0, "consistency": 0}

    def count(name, fn):
        def wrapped(*a, **k):
            calls[name] += 1
            return fn(*a, **k)
        return wrapped

    monkeypatch.setattr(vetting, "check_tightening", count("tightening", vetting.check_tightening))
    monkeypatch.setattr(vetting, "check_consistency", count("consistency", vetting.check_consistency))
    import compliance.campaign.judge as judge

    monkeypatch.setattr(judge, "check_tightening", _no_simulation)  # the judge reads the vetted notes
    reqset = load_requirements("shpp-400kw")
    prepared = pipeline.Check.of("plant-a", reqset, uncertainty=None)
    assert calls == {"tightening": len(reqset.requirements), "consistency": 1}
    assert set(prepared.vetting.loosened) == {r.id for r in reqset.requirements}


@pytest.mark.parametrize("value, message", [(1, "at least 2 plants"), (-3, "at least 2 plants"), ("mc", "expected 'local'")])
def test_bad_uncertainty_is_refused_first(value, message, monkeypatch):
    monkeypatch.setattr(pipeline, "_plant", _no_simulation)
    with pytest.raises(InputError, match=message):
        compliance.check("plant-a", "shpp-400kw", uncertainty=value)


def test_the_package_re_exports_check():
    assert compliance.check is pipeline.check and "check" in compliance.__all__ and "CheckResult" in compliance.__all__

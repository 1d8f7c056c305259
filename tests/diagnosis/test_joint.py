"""Joint diagnosis of several closed-loop recordings of one plant (diagnosis/joint.py).

The --suggest-test case: a plant whose seal friction rises with the chamber pressure
(pressure_dependent_friction, k = 1.5e-6 /Pa), recorded with the project's own simulator and
the practice sensors. At one supply pressure the mean chamber pressure hardly changes, so a
higher friction level (the recalibration ``friction.level``) is the same plant: the recording
cannot tell them apart. The test the diagnosis proposes for that case - the same steps at 70 %
of the supply - changes the chamber pressures; diagnosed jointly, only the pressure law fits both.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from compliance.cli import main
from compliance.model.config import load_plant
from compliance.diagnosis.evidence.discriminating_test import SUPPLY_FACTOR
from compliance.diagnosis.estimation.joint_residuals import JointModel
from compliance.diagnosis.servo.joint_recordings import diagnose_joint
from compliance.diagnosis.servo.selection import RESIDUAL_LIMIT
from compliance.recordings.synth import PRACTICE_NOISE, synthesise, write_recording

K_TRUE = 1.5e-6  # 1/Pa: friction levels x 1.6 at 4 bar mean gauge pressure
CANDIDATES = {"effects": ["pressure_dependent_friction"], "recalibrate": ("friction.level",)}


@pytest.fixture(scope="module")
def recordings():
    cfg = load_plant("plant-a")
    truth = cfg.replace(effects={"pressure_dependent_friction": {"coefficient": K_TRUE}})
    ps = cfg.p("air.supply_pressure")
    out = []
    # short on purpose (speed): the hold and the 2 % step and back; the second recording shorter still,
    # so the joint objective stacks blocks of different lengths
    for i, (factor, duration) in enumerate(((1.0, 8.0), (SUPPLY_FACTOR, 6.0))):
        run = truth.replace(params={"air.supply_pressure": factor * ps})
        frame, meta = synthesise(run, "steps", x0=0.06, load=7000.0, noise=PRACTICE_NOISE, seed=11 + i, duration=duration)
        meta["source_path"] = f"supply_{factor:.1f}.csv"
        out.append((frame, meta))
    return cfg, out


def test_one_supply_pressure_leaves_friction_level_and_pressure_dependence_ambiguous(recordings):
    cfg, recs = recordings
    d = diagnose_joint(cfg, recs[:1], jobs=2, **CANDIDATES)
    assert d.verdict == "ambiguous"
    assert set(d.ambiguous) == {"pressure_dependent_friction", "base"}
    for name in d.ambiguous:  # both bring every signal to its floor: the recording cannot decide
        assert max(d.objectives[name].values()) < RESIDUAL_LIMIT


def test_two_supply_pressures_resolve_it_jointly(recordings):
    cfg, recs = recordings
    d = diagnose_joint(cfg, recs, jobs=2, **CANDIDATES)
    assert d.verdict == "missing_physics" and d.winner == "pressure_dependent_friction" and not d.ambiguous
    w = d.fits[d.winner]
    assert w.values[0] == pytest.approx(K_TRUE, rel=0.1)
    # a friction level fitted to both supplies is wrong at one of them: far above its floor there
    assert d.scores["base"].chi2 > 3.0 * d.scores[d.winner].chi2
    assert max(d.objectives["base"].values()) > RESIDUAL_LIMIT
    assert max(d.objectives[d.winner].values()) < RESIDUAL_LIMIT
    # BIC counts every residual of both recordings; each recording keeps its own supply pressure
    data = d.to_dict()
    sizes = [r["n_residuals"] for r in data["recordings"]]
    assert d.n == sum(sizes) and sizes[0] > sizes[1]
    c = max(1.0, min(f.chi2 / (d.n - f.k) for f in d.fits.values()))
    assert d.scores[d.winner].bic == pytest.approx(w.chi2 / c + w.k * math.log(d.n))
    supplies = [r["conditions"]["supply_pressure"] for r in data["recordings"]]
    assert supplies[1] == pytest.approx(SUPPLY_FACTOR * supplies[0])
    assert set(data["after"]) == {"R1", "R2"}


def test_joint_model_splits_blocks_of_their_own_lengths():
    class Part:
        def __init__(self, m, signals):
            self.index, self.signals = np.arange(m), signals
            self.size = m * len(signals)

    jm = JointModel([Part(3, ("position", "pressure_a")), Part(2, ("position",))], ["R1", "R2"])
    parts = jm.split(np.arange(8.0))
    assert list(parts) == ["R1:position", "R1:pressure_a", "R2:position"]
    assert parts["R2:position"].tolist() == [6.0, 7.0] and jm.block_sizes == [3, 3, 2] and jm.size == 8


def _written(recs, folder) -> list[str]:
    """The recordings as files ``r0.csv``, ``r1.csv``, ... in ``folder``."""
    return [str(write_recording(frame, meta, folder / f"r{i}.csv")[0]) for i, (frame, meta) in enumerate(recs)]


def test_joint_cli_refuses_report_before_work(tmp_path, recordings, capsys):
    _, recs = recordings
    paths = _written(recs, tmp_path)
    out = tmp_path / "j.html"
    assert main(["diagnose", "plant-a", *paths, "--report", str(out)]) == 2
    assert "not available for a joint diagnosis" in capsys.readouterr().err and not out.exists()


def test_joint_cli_end_to_end_names_the_pressure_law(tmp_path, recordings):
    """``govcheck diagnose CONFIG R1 R2 --json``: each recording is checked against the plant, then diagnosed jointly."""
    import json

    _, recs = recordings
    paths = _written(recs, tmp_path)
    out = tmp_path / "j.json"
    assert main(["diagnose", "plant-a", *paths, "--effects", "pressure_dependent_friction", "--json", str(out),
                 "--jobs", "2", "-q"]) == 0
    data = json.loads(out.read_text())
    assert data["verdict"] == "missing_physics" and data["winner"] == "pressure_dependent_friction"
    assert [r["n_residuals"] > 0 for r in data["recordings"]] == [True, True]


def test_one_recording_on_a_dask_cluster_gives_the_local_pools_diagnosis(tmp_path, recordings):
    """``--scheduler local:2`` runs every fit of a single-recording diagnosis on Dask: same verdict and values."""
    import json

    _, recs = recordings
    path = _written(recs[1:], tmp_path)[0]
    outs = {}
    for label, extra in (("pool", ["--jobs", "2"]), ("dask", ["--scheduler", "local:2"])):
        outs[label] = tmp_path / f"{label}.json"
        assert main(["diagnose", "plant-a", str(path), "--effects", "pressure_dependent_friction",
                     "--json", str(outs[label]), "-q", *extra]) == 0
    pool, dask = (json.loads(outs[k].read_text()) for k in ("pool", "dask"))
    assert dask["verdict"] == pool["verdict"] and dask["winner"] == pool["winner"]
    assert [(e["name"], e["parameters"], e["chi2"]) for e in dask["effects"]] == \
        [(e["name"], e["parameters"], e["chi2"]) for e in pool["effects"]]
    assert dask["timing"]["simulations"] == pool["timing"]["simulations"]


def test_scheduler_is_refused_for_friction_bench_runs_before_work(tmp_path, capsys):
    from pathlib import Path

    data = Path(__file__).resolve().parents[1] / "data" / "zillen"
    runs = sorted(str(p) for p in data.glob("*.csv"))[:1]
    assert runs, "fixture of the seal bench missing"
    out = tmp_path / "f.json"
    assert main(["diagnose", *runs, "--column-map", "zillen-friction", "--scheduler", "local:2", "--json", str(out)]) == 2
    assert "--scheduler" in capsys.readouterr().err and not out.exists()


def test_a_sites_holds_name_its_leak():
    """Two hold tests of the practice site with a concealed external leak (tests/data/acceptance/site-p2): each
    closed loop for 1 s, then the valve at null with the positioner in manual; the joint fit of the leak alone."""
    from compliance.recordings.reader import read_recording

    site = Path(__file__).resolve().parents[1] / "data" / "acceptance" / "site-p2"
    recs = [read_recording(site / f"hold_{i}.csv.gz") for i in (1, 2)]
    d = diagnose_joint(load_plant("plant-a"), recs, effects=["external_leakage"], recalibrate=False, jobs=1)
    assert d.winner == "external_leakage"
    # the emulator's leak is laminar like ours (k_ext = 1e-9 kg/(s Pa)); 8.9 mm of drift in 10 s pins it
    assert d.fits["external_leakage"].value("external_leakage.conductance") == pytest.approx(1e-9, rel=0.05)
    assert not any("throttles" in n for n in d.notes)  # no full stroke: the throttles stay as the plant file sets them

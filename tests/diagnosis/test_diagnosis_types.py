"""A diagnosis, its verdicts and its worker tasks as types: built once, spelt once, sent whole."""

import pickle
from dataclasses import FrozenInstanceError, fields

import pytest

from compliance.diagnosis.servo.candidates import effect_candidate
from compliance.diagnosis.servo.parallel_fits import FitEffect, RecalibrateBase
from compliance.diagnosis.servo.report_data import Diagnosis
from compliance.diagnosis.verdicts.verdict import EXPLAINED, INCOMPLETE, DiagnosisVerdict


def test_a_diagnosis_cannot_be_changed_after_it_is_built():
    d = Diagnosis(**{f.name: None for f in fields(Diagnosis)})
    with pytest.raises(FrozenInstanceError):
        d.verdict = DiagnosisVerdict.UNEXPLAINED
    assert "explanation" not in {f.name for f in fields(Diagnosis)}  # written from the fields, not set later


def test_a_friction_bench_diagnosis_cannot_be_changed_after_it_is_built():
    from compliance.diagnosis.friction_bench.diagnose import FrictionDiagnosis, SealDiagnosis

    seal = SealDiagnosis(**{f.name: None for f in fields(SealDiagnosis)})
    whole = FrictionDiagnosis([seal], 1.0, ["a.csv"])
    with pytest.raises(FrozenInstanceError):
        seal.explanation = "set later"
    with pytest.raises(FrozenInstanceError):
        whole.seconds = 0.0


def test_diagnosis_verdicts_are_their_json_words():
    assert DiagnosisVerdict("missing_physics") is DiagnosisVerdict.MISSING_PHYSICS
    assert f"{DiagnosisVerdict.NO_MISMATCH}" == "no_mismatch"
    assert set(EXPLAINED).isdisjoint(INCOMPLETE)


def test_worker_tasks_are_frozen_records_that_travel_to_a_worker():
    task = FitEffect(effect_candidate("valve_dynamics"), screen=12.5)
    back = pickle.loads(pickle.dumps(task))
    assert back == task and back.candidate.name == "valve_dynamics" and back.screen == 12.5
    with pytest.raises(FrozenInstanceError):
        task.screen = None
    assert RecalibrateBase((), 3.0).penalty == 3.0

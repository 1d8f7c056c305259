"""Diagnosis: name the physics a model misses in a recording, model it, refit, prove it.

Public API:

- ``diagnose(cfg, frame, meta, effects=None, jobs=None)`` -> ``Diagnosis`` (servo recordings:
  replay, locate, fit every candidate, select by BIC, explain; ``to_dict()`` is the JSON of
  docs/diagnosis-schema.md) and ``save_fitted(diagnosis, path)``;
- ``diagnose_friction(runs, bore=None)`` -> ``FrictionDiagnosis`` (seal-friction bench runs);
- ``diagnose_joint(cfg, recordings)`` -> ``JointDiagnosis`` (several recordings of one
  plant: shared physics, each recording's own conditions and floors);
- ``run_benchmark(cfg, ...)`` and ``run_practice(directory, cfg)`` (the proof on generated
  concealed-effect cases and on recordings with answers).

Rooms, one job each (dependencies point down this list, never back):

- ``verdicts/``: the names a diagnosis concludes with: its verdicts (``DiagnosisVerdict``) and its
  candidate explanations (``CandidateSet``, named ``a+b+base``), parsed in one place;
- ``evidence/``: the recording against the nominal model, before any fit: the fast replay with
  matched noise, the stated operating point, noise floors, normalised residuals, where the model
  misses, the missing force outside the library, the test that would tell two explanations apart;
- ``servo/``: closed-loop servo recordings: candidates, fits, effect sets, recalibration, parallel
  fits, selection and verdicts, the lag split, the friction law's form, the explanation, the
  fitted plant, the JSON document, the chain (``servo.diagnose``) and several recordings at once;
- ``friction_bench/``: seal-friction force-bench runs (its report is compliance/report/friction.py);
- ``scoring/``: the proof against known answers: generated concealed-effect and two-effect cases,
  the benchmark, the practice recordings' score.
"""

from __future__ import annotations

__all__ = ["diagnose", "save_fitted", "Diagnosis", "diagnose_friction", "diagnose_joint", "run_benchmark", "run_practice"]


def __getattr__(name):  # lazy: importing the package does not compile the simulator
    if name in ("diagnose", "save_fitted", "Diagnosis"):
        from compliance.diagnosis.servo import diagnose as servo_diagnose

        return getattr(servo_diagnose, name)
    if name == "diagnose_friction":
        from compliance.diagnosis.friction_bench.diagnose import diagnose_friction

        return diagnose_friction
    if name == "diagnose_joint":
        from compliance.diagnosis.servo.joint_recordings import diagnose_joint

        return diagnose_joint
    if name in ("run_benchmark", "run_practice"):
        from compliance.diagnosis.scoring import benchmark

        return getattr(benchmark, name)
    raise AttributeError(name)

"""Diagnosis: name the physics a model misses in a recording, model it, refit, prove it.

Public API:

- ``diagnose(cfg, frame, meta, effects=None, jobs=None)`` -> ``Diagnosis`` (servo recordings:
  replay, locate, fit every candidate, select by BIC, explain; ``to_dict()`` is the JSON of
  docs/diagnosis-schema.md) and ``save_fitted(diagnosis, path)``;
- ``diagnose_friction(runs, bore=None)`` -> ``FrictionDiagnosis`` (seal-friction bench runs);
- ``diagnose_joint(cfg, recordings)`` -> ``JointDiagnosis`` (several closed-loop recordings of one
  plant: shared physics, each recording's own conditions and floors);
- ``run_benchmark(cfg, ...)`` and ``run_practice(directory, cfg)`` (the proof on generated
  concealed-effect cases and on recordings with answers).

Modules, one job each: ``replay_fit`` (fast re-synchronised replay with matched noise),
``operating_point`` (the stated load holds at the recording's start), ``noise_floor`` /
``residuals`` (normalised residuals), ``candidates`` (what may be fitted), ``fit`` (scan,
simplex, least squares), ``recalibration`` (base parameters), ``multi`` (several effects),
``workers`` (parallel fits), ``select`` (information criteria, honest verdicts, ambiguity),
``discriminate`` (the test that tells two explanations apart), ``split`` (does the recording
pin a lag's split or only its total), ``empirical`` (the missing force
outside the library), ``located`` (where the model misses), ``explain`` (the paragraph),
``fitted_model`` (the fitted plant), ``engine`` (the chain),
``joint`` (several recordings at once),
``concealed`` / ``benchmark`` / ``practice_score`` (the proof), ``friction_models`` / ``friction_fit`` /
``friction_position`` / ``friction_holdout`` / ``friction_diagnosis`` / ``friction_explain``
(the friction bench; its report is compliance/report/friction.py).
"""

from __future__ import annotations

__all__ = ["diagnose", "save_fitted", "Diagnosis", "diagnose_friction", "diagnose_joint", "run_benchmark", "run_practice"]


def __getattr__(name):  # lazy: importing the package does not compile the simulator
    if name in ("diagnose", "save_fitted", "Diagnosis"):
        from compliance.diagnosis import engine

        return getattr(engine, name)
    if name == "diagnose_friction":
        from compliance.diagnosis.friction_diagnosis import diagnose_friction

        return diagnose_friction
    if name == "diagnose_joint":
        from compliance.diagnosis.joint import diagnose_joint

        return diagnose_joint
    if name in ("run_benchmark", "run_practice"):
        from compliance.diagnosis import benchmark

        return getattr(benchmark, name)
    raise AttributeError(name)

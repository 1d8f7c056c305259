"""Diagnosis of seal-friction bench runs: fit the friction law, locate its failure, add the physics, refit.

Input: runs of one (or several) seals of a single-acting cylinder stroked back and forth by an
external drive at held chamber pressures (columns ``time``, ``position``, ``pressure_a``,
``force``; the Zillen bench: ``--column-map zillen-friction``). Per seal, all its pressures at
once:

1. baseline: the pressure-independent Stribeck map (plus the bench's direction-independent
   bias c0 + c1 p_g) fitted by bounded least squares to every sample, residuals normalised by
   the force sensor's noise floor;
2. locate: the baseline residual split into *after-reversal* stretches (the first
   ``runs.REVERSAL_TRAVEL`` of travel after each change of direction) and *steady sliding*; the
   friction-magnitude error sign(v)*r in steady sliding is regressed on the pressure
   (a slope says the law misses a pressure dependence) and the after-reversal RMS is compared
   with the sliding RMS (an excess says the friction does not jump at reversals: pre-sliding);
3. candidates: ``pressure_dependent_friction`` (F_C and F_S rise by k_p p_g, the core
   effect of that name), ``presliding_hysteresis`` (LuGre bristles, stiffness sigma0) and both;
   each fitted, ranked by BIC on the normalised residuals (``servo.selection.score_all``);
4. prove out of sample (``holdout``): each pressure predicted by the law refitted on the others;
   the declared bench effects (power-law pressure rise, curved pressure force, friction along the
   stroke, drift during a run) kept only when they earn their parameters there;
5. explain, per pressure before/after RMS, and the fitted law per seal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace as dc_replace

import numpy as np

from compliance.files.jsonable import json_number
from compliance.diagnosis.friction_bench.fit import BENCH_EFFECTS, LAWS, PRESLIDING, PRESSURE_EFFECT, LawFit, fit_law, law_scores
from compliance.diagnosis.friction_bench.explanation import explain_friction
from compliance.diagnosis.friction_bench.holdout import effect_words, holdout_words, pooled_holdout, prove_out_of_sample
from compliance.diagnosis.friction_bench.runs import Run, prepare_runs
from compliance.diagnosis.servo.report_data import SCHEMA
from compliance.diagnosis.friction_bench.residual_structure import friction_structure
from compliance.diagnosis.servo.selection import EXPLAINED_ENOUGH, NOISE_TOLERANCE
from compliance.diagnosis.verdicts.candidate_set import CandidateSet
from compliance.diagnosis.verdicts.verdict import DiagnosisVerdict

# a friction law is complete when its residual is within 3 x the force noise (our target for the real
# seals): the floor here is the force sensor alone, while the law is evaluated on a velocity
# differentiated from a noisy position, whose error adds ~1-2 x the force noise near the Stribeck hump
FRICTION_RESIDUAL_LIMIT = 3.0
UNITS = {"bias": "N", "bias_per_pressure": "N/Pa", "coulomb": "N", "static": "N", "stribeck_velocity": "m/s",
         "viscous": "N*s/m", "pressure_coefficient": "N/Pa", "bristle_stiffness": "N/m", "reference_position": "m",
         "reference_pressure": "Pa", **{q.name: q.unit for e in BENCH_EFFECTS for q in e.params}}
MEANING = {
    "bias": "force-sensor zero (direction-independent)",
    "bias_per_pressure": "piston-area error: direction-independent force per Pa of chamber pressure",
    "coulomb": "Coulomb friction F_C0 (at zero gauge pressure)",
    "static": "static friction F_S0 (at zero gauge pressure)",
    "stribeck_velocity": "Stribeck velocity v_s",
    "viscous": "viscous coefficient b",
    "pressure_coefficient": "rise of F_C and F_S per Pa of chamber gauge pressure, k_p",
    "bristle_stiffness": "LuGre bristle stiffness sigma0 (pre-sliding distance = F_C/sigma0)",
    "reference_position": "x_r, centre of the position-dependent friction (median position of the runs; not fitted)",
    "reference_pressure": "p_r, reference of the power-law pressure rise (median run pressure; not fitted)",
    **{q.name: q.meaning for e in BENCH_EFFECTS for q in e.params},
}


# ----------------------------------------------------------------------------- locate
def locate_friction(runs: list[Run], fit: LawFit) -> dict:
    """Where the law fails: per run sliding / after-reversal RMS, and the friction error's trend with pressure."""
    rows = []
    for r, res in zip(runs, fit.residuals):
        s = r.sliding[r.valid]
        a = (r.after_reversal & (np.abs(r.velocity) > 0))[r.valid]
        vel = r.velocity[r.valid]
        mag = res[s] * np.sign(vel[s])  # > 0: the seal rubs harder than the law says
        rows.append({
            "run": r.name, "pressure_gauge": r.pressure,
            "rms": float(np.sqrt(np.mean(res * res))),
            "rms_sliding": float(np.sqrt(np.mean(res[s] ** 2))) if s.any() else None,
            "rms_after_reversal": float(np.sqrt(np.mean(res[a] ** 2))) if a.any() else None,
            "friction_error_sliding": float(np.mean(mag)) if mag.size else None,
            "noise_floor": r.floor,
        })
    p = np.array([row["pressure_gauge"] for row in rows])
    e = np.array([row["friction_error_sliding"] if row["friction_error_sliding"] is not None else np.nan for row in rows])
    trend = None
    ok = np.isfinite(e)
    if ok.sum() >= 2 and np.ptp(p[ok]) > 0.3e5:
        A = np.vstack([np.ones(ok.sum()), p[ok]]).T
        coef, *_ = np.linalg.lstsq(A, e[ok], rcond=None)
        trend = {"slope": float(coef[1]), "unit": "N/Pa", "per_bar": float(coef[1] * 1e5),
                 "span": float(coef[1] * np.ptp(p[ok]))}
    slide = [row["rms_sliding"] for row in rows if row["rms_sliding"]]
    rev = [row["rms_after_reversal"] for row in rows if row["rms_after_reversal"]]
    ratio = (float(np.mean(rev)) / float(np.mean(slide))) if slide and rev and np.mean(slide) > 0 else None
    return {"runs": rows, "pressure_trend": trend, "reversal_excess": ratio}


# ----------------------------------------------------------------------------- diagnosis
@dataclass(frozen=True)
class SealDiagnosis:
    """The friction diagnosis of one seal (built once by ``diagnose_seal``)."""

    seal: str
    runs: list
    fits: dict
    scores: dict
    verdict: str
    winner: str | None
    runner_up: str | None
    located: dict
    located_after: dict | None
    explanation: str
    noise_floor: float
    structure: dict | None = None  # friction_structure: what the law leaves, named (empirical)
    holdout: dict | None = None  # friction_holdout: each pressure predicted by the law fitted on the others
    position: dict | None = None  # friction_holdout: does friction_along_stroke earn its parameters held out
    bench_effects: list = field(default_factory=list)  # friction_holdout: every declared bench effect tried held out

    def to_dict(self) -> dict:
        """JSON-ready (SI units; see docs/diagnosis-schema.md, friction)."""
        ranked = sorted(self.fits, key=lambda k: self.scores[k].bic)
        cands = []
        for rank, name in enumerate(ranked, 1):
            f = self.fits[name]
            s = self.scores[name]
            cands.append({
                "rank": rank, "name": name,
                "effects": list(CandidateSet.parse(name).without("baseline")),
                "parameters": [{"name": k, "value": json_number(v), "stderr": json_number(f.stderr.get(k)), "unit": UNITS[k], "meaning": MEANING[k]}
                               for k, v in f.params.items()],
                "k": f.k, "chi2": json_number(s.chi2), "chi2_per_residual": json_number(s.chi2 / f.n), "bic": json_number(s.bic),
                "delta_bic": json_number(s.delta_bic), "score": json_number(-s.delta_bic), "explained_fraction": json_number(s.explained),
                "rms_per_run": {r.name: json_number(x) for r, x in zip(self.runs, f.rms_per_run())},
            })
        base = self.fits["baseline"]
        win = self.fits.get(self.winner) if self.winner else None
        return {
            "seal": self.seal, "verdict": self.verdict, "winner": self.winner, "runner_up": self.runner_up,
            "explanation": self.explanation, "effects": cands,
            "fit_before": {r.name: {"pressure_gauge": json_number(r.pressure), "rms": json_number(b), "unit": "N"}
                           for r, b in zip(self.runs, base.rms_per_run())},
            "fit_after": ({r.name: {"pressure_gauge": json_number(r.pressure), "rms": json_number(a), "unit": "N"}
                           for r, a in zip(self.runs, win.rms_per_run())} if win else None),
            "windows": self.located, "windows_after": self.located_after,
            "noise_floor": {"value": json_number(self.noise_floor), "unit": "N"},
            "structure_left": self.structure, "holdout": self.holdout, "position_effect": self.position,
            "bench_effects": self.bench_effects,
        }




def diagnose_seal(runs: list[Run], jobs: int | None = None) -> SealDiagnosis:
    """Fit the baseline and each candidate law to one seal's runs; select; prove out of sample; explain."""
    fits = {"baseline": fit_law(runs, "baseline")}
    b = fits["baseline"].params
    warm = {"bias": b["bias"], "bias_per_pressure": b["bias_per_pressure"], "coulomb": b["coulomb"],
            "excess": max(b["static"] - b["coulomb"], 0.0), "stribeck_velocity": math.log10(b["stribeck_velocity"]),
            "viscous": b["viscous"]}
    pressures = [r.pressure for r in runs]
    can_pressure = len(runs) > 1 and (max(pressures) - min(pressures)) > 0.3e5
    for name, (pr, ps) in LAWS.items():
        if name == "baseline" or (pr and not can_pressure):
            continue
        start = dict(warm)
        if pr and ps:  # the combination starts from both single fits
            fp = fits[PRESSURE_EFFECT].params
            start.update({"bias": fp["bias"], "bias_per_pressure": fp["bias_per_pressure"], "coulomb": fp["coulomb"],
                          "excess": max(fp["static"] - fp["coulomb"], 0.0), "viscous": fp["viscous"],
                          "stribeck_velocity": math.log10(fp["stribeck_velocity"]),
                          "pressure_coefficient": fp["pressure_coefficient"],
                          "bristle_stiffness": math.log10(fits[PRESLIDING].params["bristle_stiffness"])})
        fits[name] = fit_law(runs, name, start)
    n = fits["baseline"].n
    scores = law_scores(fits, n)
    located = locate_friction(runs, fits["baseline"])
    floor = float(np.median([r.floor for r in runs]))
    rms_norm = math.sqrt(fits["baseline"].chi2 / n)
    cands = [k for k in fits if k != "baseline"]
    best = min(cands, key=lambda k: scores[k].bic, default=None)
    from compliance.diagnosis.servo.selection import MIN_GAIN, SIGNIFICANCE

    verdict, winner = DiagnosisVerdict.UNEXPLAINED, None
    if rms_norm <= NOISE_TOLERANCE:
        verdict = DiagnosisVerdict.NO_MISMATCH
    elif best is not None and scores["baseline"].bic - scores[best].bic >= SIGNIFICANCE and \
            (scores["baseline"].chi2 - scores[best].chi2) >= MIN_GAIN * max(scores["baseline"].chi2 - n, 0.0):
        winner = best
        # a simpler candidate inside the winner that is almost as good is preferred (parsimony)
        for k in cands:
            if k != best and CandidateSet.parse(k).inside(CandidateSet.parse(best)) and scores[k].bic - scores[best].bic < SIGNIFICANCE:
                winner = k
        verdict = DiagnosisVerdict.MISSING_PHYSICS if scores[winner].explained >= EXPLAINED_ENOUGH else DiagnosisVerdict.UNEXPLAINED
    proof = prove_out_of_sample(runs, fits, winner or "baseline", verdict != DiagnosisVerdict.NO_MISMATCH, jobs=jobs)
    if proof["law"] != (winner or "baseline"):  # declared bench effects earned their parameters held out and by BIC
        scores = law_scores(fits, n)
        winner = proof["law"]
        cands.append(winner)
        verdict = DiagnosisVerdict.MISSING_PHYSICS if scores[winner].explained >= EXPLAINED_ENOUGH else DiagnosisVerdict.UNEXPLAINED
    ranked = sorted(cands, key=lambda k: scores[k].bic)
    runner = next((k for k in ranked if k != winner), None)
    located_after = locate_friction(runs, fits[winner]) if winner else None
    after = math.sqrt(fits[winner].chi2 / n) if winner else rms_norm
    if verdict == DiagnosisVerdict.MISSING_PHYSICS and after > FRICTION_RESIDUAL_LIMIT:
        verdict = DiagnosisVerdict.PARTIALLY_EXPLAINED  # as select.honest: complete only within the stated multiple of the noise
    structure = friction_structure(runs, fits[winner or "baseline"]) if verdict != DiagnosisVerdict.NO_MISMATCH else None
    diag = SealDiagnosis(runs[0].seal, runs, fits, scores, verdict, winner, runner, located, located_after, "", floor,
                         structure=structure, holdout=proof["holdout"], position=proof["position"],
                         bench_effects=proof["effects"])
    words = explain_friction(diag)  # the explanation is written from every other field
    if structure:
        words += (f" The law leaves {after:.1f} times the force noise (complete only within {FRICTION_RESIDUAL_LIMIT:g});"
                  f" empirical suggestion, not a declared effect: {structure['words']}")
    if diag.holdout:
        words += holdout_words(diag.holdout, diag.seal) + effect_words(diag.bench_effects)
    return dc_replace(diag, explanation=words)


@dataclass(frozen=True)
class FrictionDiagnosis:
    """Friction diagnosis of every seal in the files given (built once by ``diagnose_friction``)."""

    seals: list = field(default_factory=list)
    seconds: float = 0.0
    files: list = field(default_factory=list)

    def to_dict(self) -> dict:
        """JSON document (docs/diagnosis-schema.md, ``kind = "friction"``)."""
        verdicts = [s.verdict for s in self.seals]
        worst_first = (DiagnosisVerdict.UNEXPLAINED, DiagnosisVerdict.PARTIALLY_EXPLAINED, DiagnosisVerdict.MISSING_PHYSICS)
        overall = next((v for v in worst_first if v in verdicts), DiagnosisVerdict.NO_MISMATCH)
        return {"schema": SCHEMA, "kind": "friction", "recordings": self.files, "verdict": overall,
                "seals": [s.to_dict() for s in self.seals], "holdout_pooled": pooled_holdout([s.holdout for s in self.seals]),
                "timing": {"seconds": self.seconds}}


def diagnose_friction(runs, *, bore: float | None = None, jobs: int | None = None) -> FrictionDiagnosis:
    """Diagnose friction-bench runs, grouped per seal (file name before the pressure).

    Parameters
    ----------
    runs : sequence of (DataFrame, metadata)
    bore : float, optional
        Piston bore [m] (else from the metadata).
    jobs : int, optional
        Worker processes of the held-out fits (default: the available cores).
    """
    import time as _time

    t0 = _time.perf_counter()
    prepared = prepare_runs(runs, bore)
    groups: dict[str, list[Run]] = {}
    for r in prepared:
        groups.setdefault(r.seal, []).append(r)
    seals = [diagnose_seal(sorted(rs, key=lambda r: r.pressure), jobs) for rs in groups.values()]
    return FrictionDiagnosis(seals, _time.perf_counter() - t0, [str(m.get("source_path", "")) for _, m in runs])

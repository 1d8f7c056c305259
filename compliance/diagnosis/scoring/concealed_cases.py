"""Concealed-effect recordings from the model: the proving ground of the diagnosis.

A case is a closed-loop practice test (``recording_synth``: 2 s hold, 2/5/10 % steps and
back, 8 mm sinusoid) on plant A at a random operating point (initial position, closing
load, derivative gain), with realistic sensors (position N(0, 20 um) + 10 um steps,
pressures N(0, 300 Pa) + 16 bits over 0-10 bar, exact command), and one of:

- an effect switched on, its parameters drawn in ``EFFECT_RANGES`` and *accepted only when
  concealed*: the measured position moves by at most ``MAX_POSITION_RMS`` from the same run
  without the effect (the controller hides it), while a pressure, the supply pressure or the
  command moves by at least ``MIN_PRESSURE_RMS`` / ``MIN_COMMAND_RMS``, and the nominal
  model's re-synchronised replay of the noisy recording leaves at least ``VISIBLE_LEVEL``
  times the noise floor on a pressure, the supply pressure or the command, which the true
  model at least halves (the signature is there and it is the effect's, above the noise a
  correct model leaves, not only in a diverging long run);
- a miscalibrated base parameter (``MISCALIBRATIONS``), recorded with the wrong value and
  diagnosed with the nominal one: the right answer is "parameters_only";
- nothing (a null case): the right answer is "no_mismatch".
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from compliance.model.config import PlantConfig
from compliance.effects import EFFECTS
from compliance.errors import SimulationError
from compliance.validation.replay_conditions import load_at_start
from compliance.recordings.synth import PRACTICE_NOISE, practice_profile, synthesise
from compliance.simulation import Scenario
from compliance.plants import simulate

MAX_POSITION_RMS = 0.5e-3  # m; concealed: the position moves less than this (practice cases: 0.13-0.50 mm)
MIN_PRESSURE_RMS = 3.0e3  # Pa; visible: ten times the pressure sensor noise (practice cases: 4-13 kPa)
MIN_COMMAND_RMS = 0.08  # V; visible in the command (practice cases: 0.12-0.44 V)
VISIBLE_LEVEL = 2.5  # normalised RMS of the nominal replay on a pressure or the command (no_mismatch ends at 1.5)
MAX_TRUTH_RATIO = 0.5  # the true model must at least halve the nominal chi-square (the signature is the effect's)
MAX_DRAWS = 20  # tries per case before the range is declared unable to conceal
PRE_ROLL = 2.0  # s of hold simulated before the recording starts (the bench has settled)

# effect -> parameter -> (low, high, log) (``Effect.draw``); parameters not named keep their declared default
EFFECT_RANGES: dict[str, dict[str, tuple[float, float, bool]]] = {name: dict(eff.draw) for name, eff in EFFECTS.items()}
SIGNED = tuple(name for name, eff in EFFECTS.items() if eff.draw_signed)  # sign of the first parameter drawn separately
# base parameter -> multiplicative factors drawn from (low, high) or its reciprocal range
MISCALIBRATIONS: dict[str, tuple[float, float]] = {
    "valve.sonic_conductance": (1.3, 1.7),
    "friction.level": (1.3, 1.8),
    "cylinder.dead_volume": (1.4, 2.0),
    "cylinder.moving_mass": (2.0, 4.0),
}


@dataclass
class Case:
    """One generated recording and its truth.

    Attributes
    ----------
    kind : str
        ``effect``, ``null`` or ``miscalibration``.
    truth : str
        Effect name, ``none``, or the miscalibrated base key.
    params : dict
        True effect parameters [SI] (or {key: true value} for a miscalibration).
    frame : pandas.DataFrame
    meta : dict
    operating_point : dict
        x0 [m], load [N], kd [V*s/m], seed.
    visibility : dict
        RMS change of each signal caused by the truth (same run without it) [SI].
    """

    kind: str
    truth: str
    params: dict
    frame: object
    meta: dict
    operating_point: dict
    visibility: dict = field(default_factory=dict)
    visible: bool = True  # False: no draw was both concealed and visible (the case tests nothing; scored apart)


def _draw(rng, lo, hi, log) -> float:
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi)))) if log else float(rng.uniform(lo, hi))


def draw_operating_point(rng, stroke: float) -> dict:
    """Random practice-test operating point: start position, closing load, derivative gain."""
    x0 = float(rng.uniform(0.03, stroke - 0.03))
    load = float(rng.uniform(1000.0, 11000.0))
    kd = float(rng.choice([6.0, 20.0]))
    return {"x0": round(x0, 4), "load": round(load, 0), "kd": kd}


def draw_effect_params(rng, name: str) -> dict:
    """Random parameters of an effect within ``EFFECT_RANGES`` (and the effect's declared bounds)."""
    out = {}
    for p, (lo, hi, log) in EFFECT_RANGES[name].items():
        blo, bhi = EFFECTS[name].param(p).bounds
        lo, hi = max(lo, blo), min(hi, bhi)
        v = _draw(rng, lo, hi, log) if hi > lo else lo
        if name in SIGNED and p == EFFECTS[name].params[0].name and rng.uniform() < 0.5:
            v = -v
        out[p] = v
    return out


def _clean_run(cfg: PlantConfig, op: dict):
    stroke = cfg.p("cylinder.stroke")
    ref = practice_profile(op["x0"], stroke)
    c = cfg.replace(params={"controller.kd": op["kd"]})
    return simulate(c, Scenario(duration=30.0, initial_position=op["x0"], reference=ref,
                                load=load_at_start(c, op["load"], op["x0"])))


def visibility(cfg_truth: PlantConfig, cfg_nominal: PlantConfig, op: dict) -> dict:
    """RMS change of each measured signal between the truth and the nominal model (noise-free)."""
    a = _clean_run(cfg_truth, op)
    b = _clean_run(cfg_nominal, op)
    return {s: float(np.sqrt(np.mean((a[s].to_numpy() - b[s].to_numpy()) ** 2)))
            for s in ("position", "pressure_a", "pressure_b", "supply_pressure", "valve_command")}


def is_concealed(vis: dict) -> bool:
    """Hidden in the position, visible in a pressure or the command."""
    pressure = max(vis["pressure_a"], vis["pressure_b"], vis["supply_pressure"])
    return vis["position"] <= MAX_POSITION_RMS and (pressure >= MIN_PRESSURE_RMS or vis["valve_command"] >= MIN_COMMAND_RMS)


def _record(cfg_truth: PlantConfig, op: dict, seed: int, description: str):
    """The noisy practice recording of a truth, starting at rest.

    The simulator starts from its at-rest trim, which is not a rest state when an effect
    adds states the trim does not set (a relaxed linkage under load, leaking chambers); a
    bench recording starts after the servo has settled. So the test is simulated with a
    ``PRE_ROLL`` hold in front and the recording starts after it.
    """
    from compliance.simulation.profiles import Profile

    ref = practice_profile(op["x0"], cfg_truth.p("cylinder.stroke"))
    shifted = Profile(ref.times + PRE_ROLL, ref.values)
    # the stated load is the load at the start position (validation/replay_conditions.py), as a bench states it
    frame, meta = synthesise(cfg_truth, "practice", x0=op["x0"], load=load_at_start(cfg_truth, op["load"], op["x0"]),
                             kd=op["kd"], noise=PRACTICE_NOISE, seed=seed, description=description,
                             duration=30.0 + PRE_ROLL, reference=shifted)
    meta["conditions"]["load_force"] = float(op["load"])
    ts = meta["controller"]["sample_time"]
    k0 = int(round(PRE_ROLL / ts))
    frame = frame.iloc[k0:].reset_index(drop=True)
    frame["time"] = frame["time"] - frame["time"].iloc[0]
    frame.attrs = {}
    meta["conditions"]["initial_position"] = float(frame["position"].iloc[:50].median())
    return frame, meta


def replay_visibility(cfg: PlantConfig, frame, meta, truth: PlantConfig | None = None) -> dict:
    """What the recording shows the nominal model: normalised RMS of its re-synchronised replay per
    signal, and (with ``truth``) the chi-square ratio truth / nominal (how much the true model explains)."""
    from compliance.validation.replay import prepare_replay, run_replay
    from compliance.diagnosis.evidence.residuals import build_residual_model, signal_fit

    setup = prepare_replay(cfg, frame, meta)
    rc = setup.config(cfg)
    model = build_residual_model(rc, setup)
    nom = run_replay(rc, setup)
    out = {s: v["rms_normalised"] for s, v in signal_fit(model, nom).items()}
    if truth is not None:
        vn = model.vector(nom)
        vt = model.vector(run_replay(setup.config(truth), setup))
        out["truth_ratio"] = float(np.dot(vt, vt) / np.dot(vn, vn))
    return out


def _visible(norm: dict) -> bool:
    """The signature stands above the floor on a pressure or the command, and the true model explains it."""
    level = max((v for s, v in norm.items() if s not in ("position", "truth_ratio")), default=0.0)
    return level >= VISIBLE_LEVEL and norm.get("truth_ratio", 0.0) <= MAX_TRUTH_RATIO


def effect_case(cfg: PlantConfig, name: str, seed: int) -> Case:
    """A concealed-effect case (rejection sampling over parameters and operating points)."""
    rng = np.random.default_rng(seed)
    stroke = cfg.p("cylinder.stroke")
    last = None
    for _ in range(MAX_DRAWS):
        op = draw_operating_point(rng, stroke)
        params = draw_effect_params(rng, name)
        truth = cfg.replace(effects={name: params})
        try:
            vis = visibility(truth, cfg, op)
            if not is_concealed(vis):
                continue
            frame, meta = _record(truth, op, seed, f"concealed {name} case (seed {seed})")
            norm = replay_visibility(cfg, frame, meta, truth)
        except SimulationError:
            continue
        last = (op, params, vis, frame, meta, norm)
        if _visible(norm):
            break
    if last is None:
        raise SimulationError(f"no concealed draw of {name} in {MAX_DRAWS} tries (seed {seed})")
    op, params, vis, frame, meta, norm = last
    vis = dict(vis, replay_normalised=norm)
    return Case("effect", name, params, frame, meta, {**op, "seed": seed}, vis, visible=_visible(norm))


def null_case(cfg: PlantConfig, seed: int) -> Case:
    """A recording of the nominal model itself (the diagnosis must say no_mismatch)."""
    rng = np.random.default_rng(seed)
    op = draw_operating_point(rng, cfg.p("cylinder.stroke"))
    frame, meta = _record(cfg, op, seed, f"null case (seed {seed})")
    return Case("null", "none", {}, frame, meta, {**op, "seed": seed}, {})


def miscalibration_case(cfg: PlantConfig, key: str, seed: int) -> Case:
    """A recording with one base parameter off by a drawn factor (the diagnosis must refit it)."""
    rng = np.random.default_rng(seed)
    last = None
    for _ in range(MAX_DRAWS):
        op = draw_operating_point(rng, cfg.p("cylinder.stroke"))
        lo, hi = MISCALIBRATIONS[key]
        f = _draw(rng, lo, hi, True)
        if rng.uniform() < 0.5:
            f = 1.0 / f
        if key == "friction.level":
            params = {"friction.static_force": cfg.p("friction.static_force") * f,
                      "friction.coulomb_force": cfg.p("friction.coulomb_force") * f}
            truth_value = f
        else:
            params = {key: cfg.p(key) * f}
            truth_value = params[key]
        truth = cfg.replace(params=params)
        try:
            vis = visibility(truth, cfg, op)
            frame, meta = _record(truth, op, seed, f"miscalibrated {key} x{f:.2f} (seed {seed})")
            norm = replay_visibility(cfg, frame, meta, truth)
        except SimulationError:
            continue
        last = (op, f, truth_value, vis, frame, meta, norm)
        if max(v for k, v in norm.items() if k != "truth_ratio") >= VISIBLE_LEVEL and norm["truth_ratio"] <= MAX_TRUTH_RATIO:
            break
    if last is None:
        raise SimulationError(f"no simulable miscalibration of {key} in {MAX_DRAWS} tries (seed {seed})")
    op, f, truth_value, vis, frame, meta, norm = last
    visible = max(v for k, v in norm.items() if k != "truth_ratio") >= VISIBLE_LEVEL and norm["truth_ratio"] <= MAX_TRUTH_RATIO
    return Case("miscalibration", key, {key: truth_value, "factor": f}, frame, meta, {**op, "seed": seed},
                dict(vis, replay_normalised=norm), visible=visible)

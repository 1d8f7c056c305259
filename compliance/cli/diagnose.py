"""``govcheck diagnose``: name the physics a model misses in a recording, model it, refit, show the gain.

    govcheck diagnose [CONFIG] RECORDING [--column-map MAP] [--json out.json]
                      [--report diag.html] [--save-model fitted.toml] [--effects a,b,c] [--jobs N]
    govcheck diagnose FILE1 FILE2 ... --column-map zillen-friction --friction-bore "25.7 mm"

A servo recording (time, position, valve command; reference for a closed-loop test) gets the
replay diagnosis (``compliance.diagnosis.servo.diagnose``); friction-bench recordings (position,
chamber pressure and drive force, no valve command) get the friction-model diagnosis
(``compliance.diagnosis.friction_bench.diagnose``). Exit 0 when the diagnosis ran (whatever it
found), 2 on bad input.
"""

from __future__ import annotations

from pathlib import Path

from compliance.cli.common import (add_recording_inputs, add_parser, add_jobs, add_outputs, add_quiet, add_reproducible, check_args_outputs,
                                   check_sidecar_conditions, sidecar_plant, split_config, add_document_options,
                                   document_options, add_scheduler, check_scheduler)
from compliance.errors import InputError
from compliance.files.atomic import write_json_atomic

_SCALE = {"position": (1e3, "mm"), "valve_command": (1.0, "V"), "pressure_a": (1e-3, "kPa"), "pressure_b": (1e-3, "kPa"),
          "supply_pressure": (1e-3, "kPa")}


def register(sub):
    """Add the ``diagnose`` command."""
    p = add_parser(
        sub, "diagnose",
        help="find the physics a model misses in a recording (or which parameter is off), fit it, show the gain",
        description=(
            "Replay the recording through the model, locate where it disagrees, then fit every candidate "
            "explanation - each declared effect (heat transfer, leakage, valve dynamics, supply droop, ...) and the "
            "recalibration of base parameters - by bounded least squares, rank them by BIC on residuals normalised by "
            "each signal's noise floor, and explain the winner. Friction-bench recordings (position, chamber pressure "
            "and force; no valve command) get a friction-model diagnosis instead."
        ),
        examples=[
            "govcheck diagnose models/plant-a.toml run.csv.gz --json diag.json",
            "govcheck diagnose plant-a run.csv.gz --effects heat_transfer,internal_leakage --save-model fitted.toml",
            "govcheck diagnose tests/data/practice/practice_valve_dynamics.csv.gz --report diag.html",
            "govcheck diagnose O-ring257_*bar.csv --column-map zillen-friction --friction-bore '25.7 mm' --report f.html",
            "govcheck diagnose plant-a run-8bar.csv run-5.6bar.csv --json joint.json   # shared physics, each run's conditions",
        ],
        usage="govcheck diagnose [options] [CONFIG] RECORDING [RECORDING ...]",
    )
    add_recording_inputs(p, "the recording file(s); several recordings of one plant are diagnosed jointly")
    p.add_argument("--effects", help="comma-separated candidate effects (default: every declared effect)")
    p.add_argument("--no-recalibration", action="store_true", help="do not consider recalibrating base parameters")
    add_jobs(p)
    add_scheduler(p, "the candidate fits (of one recording or of several jointly)")
    p.add_argument("--friction-bore", help='friction bench: piston bore, e.g. "25.7 mm" (else the column map\'s metadata)')
    add_outputs(p, "json", "report", "pdf", help={"json": "write the diagnosis (docs/diagnosis-schema.md) to FILE.json",
                                                  "report": "write an HTML report with the before/after figures to FILE.html",
                                                  "pdf": "write the same report as an A4 PDF to FILE.pdf"})
    add_document_options(p)
    p.add_argument("--save-model", metavar="FILE.toml", help="write the fitted plant configuration here (never overwrites; "
                                                            "nothing is saved when the diagnosis finds no mismatch)")
    add_quiet(p, "print only the verdict line")
    add_reproducible(p)
    p.add_argument("--suggest-test", action="store_true",
                   help="design and print the test that best tells the two leading explanations apart")
    return p


def _is_friction(frame) -> bool:
    return "valve_command" not in frame.columns and "force" in frame.columns


def run(args) -> int:
    """Run ``govcheck diagnose``; returns 0 when the diagnosis ran."""
    from compliance.recordings.reader import read_recording

    plant_arg, args.recordings = split_config(args, args.inputs)
    check_args_outputs(args, (args.save_model, "--save-model", (".toml",)))
    if args.save_model and Path(args.save_model).exists():
        raise InputError(f"--save-model {args.save_model}: exists already; choose another name (nothing is overwritten)")
    effects = None
    if args.effects is not None:  # given but empty ("") is a mistake, not "every effect"
        effects = [e.strip() for e in args.effects.split(",") if e.strip()]
        if not effects:
            raise InputError("--effects '': expected a comma-separated list of effect names (leave --effects out for every effect)")
    first, meta = read_recording(args.recordings[0], args.column_map, required=("time",))
    if _is_friction(first):
        return _run_friction(args, first, meta)
    if args.friction_bore is not None:
        raise InputError(f"--friction-bore {args.friction_bore}: the bore of a friction-bench run, and "
                         f"{args.recordings[0]} is a servo recording (it has a valve command); drop --friction-bore")
    if len(args.recordings) > 1:
        return _run_joint(args, plant_arg, effects)
    frame, meta = read_recording(args.recordings[0], args.column_map)
    from compliance.model.config import load_plant
    from compliance.diagnosis.servo.diagnose import diagnose, save_fitted

    plant = plant_arg or sidecar_plant(meta, args.recordings[0])
    if not plant:
        raise InputError(f"{args.recordings[0]}: no CONFIG given and the sidecar names no 'plant'")
    cfg = load_plant(plant)
    check_sidecar_conditions(cfg, frame, meta, args.recordings[0])
    check_scheduler(args)  # a bad address is exit 2 before any work
    from compliance.diagnosis.servo.stage import check_effects
    from compliance.cli.progress import progress

    check_effects(cfg, effects)  # an unknown effect name is exit 2 before the progress bar and any replay
    with progress(1, "diagnose", quiet=args.quiet, unit="stage", first="replay, locate, fit every candidate") as bar:
        diag = diagnose(cfg, frame, meta, effects=effects, jobs=args.jobs, recalibrate=not args.no_recalibration,
                        suggest_test=args.suggest_test, scheduler=args.scheduler)
        bar.update(1)
    unsaved = saved = None
    if args.save_model:
        if diag.fitted_cfg is None:
            unsaved = f"--save-model {args.save_model}: not written: the verdict is '{diag.verdict}', so there is no fitted model to save"
        else:
            saved = str(save_fitted(diag, args.save_model))
    data = diag.to_dict(saved_model=saved)
    if args.json:
        write_json_atomic(args.json, _finish(data, args))
    if args.report or args.pdf:
        _render_servo_report(cfg, frame, meta, diag, data, args)
    _print_servo(data, args.quiet)
    if unsaved:
        print(f"note: {unsaved}")
    if args.suggest_test:
        from compliance.diagnosis.evidence.discriminating_test import suggestion_lines

        print("\n".join(suggestion_lines(diag.suggested_test)))
    return 0


def _finish(data: dict, args) -> dict:
    from compliance.files.reproducible import is_reproducible, make_reproducible

    return make_reproducible(data) if is_reproducible(args.reproducible) else data


def _print_servo(d: dict, quiet: bool) -> None:
    print(f"verdict: {d['verdict']}" + (f" ({d['winner']})" if d.get("winner") else "") + f" - {d['reason']}")
    if quiet:
        return
    print()
    print(d["explanation"])
    print()
    print(f"{'candidate':34s} {'k':>2s} {'chi2/N':>9s} {'dBIC':>10s} {'explained':>9s}  parameters")
    for e in d["effects"][:8]:
        params = ", ".join(f"{p['name'].split('.')[-1]}={p['value']:.4g} {p['unit']}".rstrip() for p in e["parameters"])
        print(f"{e['name']:34s} {e['k']:2d} {e['chi2_per_residual']:9.3f} {e['delta_bic']:10.1f} {100*(e['explained_fraction'] or 0):8.0f}%  {params}")
    print()
    print(f"{'signal':16s} {'RMS before':>12s} {'RMS after':>12s} {'fit % before':>13s} {'fit % after':>12s}")
    for s, b in (d["fit_before"] or {}).items():
        sc, unit = _SCALE[s]
        a = (d.get("fit_after") or {}).get(s)
        after = f"{a['rms']*sc:9.3g} {unit:3s}" if a else f"{'-':>12s}"
        fa = f"{a['fit_percent']:12.1f}" if a and a.get("fit_percent") is not None else f"{'-':>12s}"
        fb = f"{b['fit_percent']:13.1f}" if b.get("fit_percent") is not None else f"{'-':>13s}"
        print(f"{s:16s} {b['rms']*sc:9.3g} {unit:3s}{after}{fb}{fa}")
    t = d["timing"]
    print(f"\n{len(d['windows'])} located windows; {t['simulations']} simulations in {t['seconds']:.1f} s on {t['jobs']} worker(s)")
    if d.get("saved_model"):
        print(f"fitted model written to {d['saved_model']}")


def _render_servo_report(cfg, frame, meta, diag, data: dict, args) -> None:
    from compliance.model.identity import identity_dict
    from compliance.diagnosis.servo.report_data import validation_with_diagnosis
    from compliance.report.render import render_validation_report

    result = validation_with_diagnosis(cfg, frame, meta, diag, data)
    document = {**document_options(args), "identity": identity_dict(cfg.identity)}
    render_validation_report(result, args.report, args.pdf, document=document)


def _run_friction(args, first, meta) -> int:
    from compliance.diagnosis.friction_bench.diagnose import diagnose_friction
    from compliance.diagnosis.friction_bench.explanation import format_friction
    from compliance.recordings.reader import read_recording
    from compliance.units import parse_quantity

    if args.save_model:
        raise InputError("--save-model: a friction-bench diagnosis fits a friction law, not a plant configuration; use --json")
    if args.scheduler:
        raise InputError("--scheduler: friction-bench runs are fitted on the local process pool (seconds per seal); use --jobs")
    for flag, value in (("--effects", args.effects), ("--no-recalibration", args.no_recalibration or None),
                        ("--suggest-test", args.suggest_test or None)):
        if value is not None:
            raise InputError(f"{flag}: shapes the diagnosis of a servo recording, and {args.recordings[0]} is a "
                             "friction-bench run (force, no valve command), fitted with the friction laws; drop it")
    runs = [(first, meta)]
    for path in args.recordings[1:]:
        f, m = read_recording(path, args.column_map, required=("time",))
        if not _is_friction(f):
            raise InputError(f"{path}: not a friction-bench run like {args.recordings[0]} (needs force and no valve command)")
        runs.append((f, m))
    bore = parse_quantity(args.friction_bore, "m", "--friction-bore") if args.friction_bore else None
    result = diagnose_friction(runs, bore=bore, jobs=args.jobs)
    data = result.to_dict()
    if args.json:
        write_json_atomic(args.json, _finish(data, args))
    if args.report or args.pdf:
        from compliance.report.friction import write_friction_report

        bench = {k: str(v) for k, v in (meta or {}).items() if k in ("rig", "seal", "temperature", "operator", "date")}
        bench.setdefault("rig", str((meta or {}).get("description") or "") or None)
        if bore is not None:
            bench["bore"] = f"{bore * 1e3:.3g} mm"
        elif (meta or {}).get("bore"):
            bench["bore"] = str(meta["bore"])
        write_friction_report(result, args.report, args.pdf, document=document_options(args), bench=bench)
    print(format_friction(data, args.quiet))
    return 0


def refuse_joint_options(args) -> None:
    """The outputs and options a joint diagnosis of several recordings does not make are refused, not dropped."""
    for flag, value in (("--save-model", args.save_model), ("--report", args.report), ("--pdf", args.pdf),
                        ("--suggest-test", args.suggest_test), ("--document-number", args.document_number),
                        ("--revision", args.revision)):
        if value:
            raise InputError(f"{flag}: not available for a joint diagnosis of several recordings (use --json)")


def check_distinct_recordings(paths) -> None:
    """Each recording of a joint diagnosis once: the same file twice, or a byte-identical copy under another name,
    would count one test as two."""
    import hashlib

    by_name: dict = {}
    by_bytes: dict = {}
    for path in paths:
        p = Path(path)
        key = p.resolve()
        if key in by_name:
            raise InputError(f"{path}: given twice; a joint diagnosis needs different recordings of the plant")
        by_name[key] = path
        if not p.is_file():
            continue  # the reader names a missing file
        digest = hashlib.sha256(p.read_bytes()).hexdigest()
        if digest in by_bytes:
            raise InputError(f"{path}: the same bytes as {by_bytes[digest]} (a copy under another name); a joint diagnosis "
                             "needs different recordings of the plant")
        by_bytes[digest] = path


def one_sidecar_plant(paths, recs, required: bool = True) -> str | None:
    """The plant the recordings' sidecars name: one and the same for all, or an error naming the two that differ.

    With ``required`` (no CONFIG given) every sidecar must name it; otherwise sidecars that name none are left be.
    """
    named = [(path, sidecar_plant(meta, path)) for path, (_, meta) in zip(paths, recs)]
    given = [(path, plant) for path, plant in named if plant]
    if not given:
        if required:
            raise InputError(f"{paths[0]}: no CONFIG given and the sidecar names no 'plant'")
        return None
    first_path, first = given[0]
    for path, plant in given[1:]:
        if _same_plant(plant, first):
            continue
        raise InputError(f"{path}: its sidecar names plant '{plant}', and {first_path}'s names '{first}'; a joint diagnosis "
                         "fits one plant to recordings of that one plant (correct the sidecar that is wrong)")
    missing = [path for path, plant in named if not plant]
    if missing and required:
        raise InputError(f"{missing[0]}: its sidecar names no 'plant' while {first_path}'s names '{first}'; give CONFIG")
    return first


def _same_plant(a: str, b: str) -> bool:
    import os

    return a == b or (os.path.isfile(a) and os.path.isfile(b) and os.path.samefile(a, b))


def _run_joint(args, plant_arg, effects) -> int:
    """Several recordings of one plant: one diagnosis with shared physics (diagnosis.servo.joint_recordings)."""
    from compliance.cli.progress import progress
    from compliance.diagnosis.servo.joint_recordings import diagnose_joint, format_joint
    from compliance.model.config import load_plant
    from compliance.recordings.reader import read_recording

    refuse_joint_options(args)
    check_scheduler(args)  # a bad address is exit 2 before any work
    check_distinct_recordings(args.recordings)
    recs = [read_recording(path, args.column_map) for path in args.recordings]
    named = one_sidecar_plant(args.recordings, recs, required=not plant_arg)
    cfg = load_plant(plant_arg or named)
    for path, (frame, meta) in zip(args.recordings, recs):
        check_sidecar_conditions(cfg, frame, meta, path)
    with progress(1, "diagnose", quiet=args.quiet, unit="stage", first=f"{len(recs)} recordings, shared physics") as bar:
        diag = diagnose_joint(cfg, recs, effects=effects, jobs=args.jobs, scheduler=args.scheduler,
                              recalibrate=not args.no_recalibration)
        bar.update(1)
    data = diag.to_dict()
    if args.json:
        write_json_atomic(args.json, _finish(data, args))
    print(format_joint(data, args.quiet))
    return 0

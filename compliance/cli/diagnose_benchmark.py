"""``govcheck diagnose-benchmark``: prove the diagnosis on generated concealed-effect recordings.

    govcheck diagnose-benchmark [CONFIG] [--cases N] [--seed S] [--effects a,b] [--library a,b] [--jobs N] [--scheduler ADDR]
                                [--no-null] [--no-miscalibrations] [--practice DIR] [--json out.json]
                                [--markdown results.md]

Generates N concealed cases per effect (plus null and miscalibrated-parameter cases) from the
plant model, diagnoses each, and prints the confusion matrix, top-1 accuracy, null accuracy,
median fit improvement and parameter recovery. ``--practice DIR`` diagnoses the recordings of a
directory instead and scores them against its ANSWERS.json. Exit 0 when the targets are met
(top-1 >= 90 %, null >= 90 %; all practice recordings right), 1 when not, 2 on bad input.
``--markdown FILE.md`` writes the same results as Markdown tables (the measured tables of
docs/diagnosis.md are made this way).
"""

from __future__ import annotations

import argparse

from compliance.cli.common import (add_jobs, add_outputs, add_plant_argument, add_quiet, add_reproducible, add_scheduler,
                                   check_args_outputs, check_scheduler, plant_from_args)
from compliance.errors import InputError

TOP1_TARGET = 0.9
NULL_TARGET = 0.9


def register(sub):
    """Add the ``diagnose-benchmark`` command."""
    p = sub.add_parser(
        "diagnose-benchmark",
        help="score the diagnosis on generated concealed-effect recordings (or on a directory with answers)",
        description=(
            "Generate closed-loop practice tests from the plant model at random operating points with realistic "
            "sensors, each with one concealed effect (hidden in the position, visible in pressures or command), "
            "null cases and miscalibrated base parameters; diagnose each and score."
        ),
        epilog=(
            "examples:\n"
            "  govcheck diagnose-benchmark --cases 3 --seed 1 --json bench.json\n"
            "  govcheck diagnose-benchmark --effects heat_transfer,internal_leakage --cases 2 --jobs 2\n"
            "  govcheck diagnose-benchmark --cases 3 --scheduler local:2\n"
            "  govcheck diagnose-benchmark models/plant-a.toml --practice tests/data/practice\n"
            "  govcheck diagnose-benchmark --practice tests/data/practice --reproducible --markdown practice.md"
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    add_plant_argument(p, help="plant configuration the cases are generated from and diagnosed against (default plant-a)")
    p.add_argument("--cases", type=int, default=None, help="cases per effect and null cases (default 3)")
    p.add_argument("--seed", type=int, default=None, help="seed of the case generator (default 1)")
    p.add_argument("--effects", help="effects to generate cases of (default: all declared)")
    p.add_argument("--library", help="candidate effects the diagnosis chooses from (default: all declared)")
    add_jobs(p, "cases diagnosed in parallel")
    add_scheduler(p, "the cases (with --practice: the recordings)")
    p.add_argument("--no-null", action="store_true", help="no null cases")
    p.add_argument("--no-miscalibrations", action="store_true", help="no miscalibrated-parameter cases")
    p.add_argument("--practice", help="diagnose the recordings of this directory and score them against its ANSWERS.json")
    add_outputs(p, "json", help={"json": "write every case and the summary to FILE.json"})
    p.add_argument("--markdown", metavar="FILE.md",
                   help="write the results as Markdown tables to FILE.md (without times under --reproducible)")
    add_quiet(p, "no per-case lines; print only the summary")
    add_reproducible(p)
    return p


def _names(text: str | None, option: str):
    from compliance.effects import EFFECTS

    if not text:
        return None
    names = [x.strip() for x in text.split(",") if x.strip()]
    for n in names:
        if n not in EFFECTS:
            raise InputError(f"{option}: '{n}' is not a declared effect (known: {', '.join(EFFECTS)})")
    return names


MARKDOWN_OUTPUT = ("--markdown", (".md", ".markdown"))


def _write(args, data: dict, markdown) -> None:
    """The ``--json`` and ``--markdown`` outputs (``markdown(data, timings)`` formats the tables)."""
    from compliance.files.atomic import write_json_atomic, write_text_atomic
    from compliance.files.reproducible import is_reproducible, make_reproducible

    reproducible = is_reproducible(args.reproducible)
    if args.json:
        write_json_atomic(args.json, make_reproducible(data) if reproducible else data)
    if args.markdown:
        write_text_atomic(args.markdown, markdown(data, timings=not reproducible))


def run(args) -> int:
    """Run the benchmark; 0 when the targets are met, 1 when not."""
    from compliance.diagnosis.scoring.benchmark import format_summary, run_benchmark, run_practice
    from compliance.processes import available_cores

    check_args_outputs(args, (args.markdown, *MARKDOWN_OUTPUT))
    scheduler = check_scheduler(args)
    if args.practice:  # recordings, not generated cases: the generator's options would do nothing
        for flag, value in (("--cases", args.cases), ("--seed", args.seed), ("--effects", args.effects),
                            ("--no-null", args.no_null or None), ("--no-miscalibrations", args.no_miscalibrations or None)):
            if value is not None:
                raise InputError(f"{flag}: shapes the generated cases, and --practice diagnoses recordings instead; "
                                 f"drop {flag} or --practice")
    args.cases = 3 if args.cases is None else args.cases
    args.seed = 1 if args.seed is None else args.seed
    if args.cases < 1:
        raise InputError(f"--cases {args.cases}: expected at least 1")
    if not 0 <= args.seed < 2**32:
        raise InputError(f"--seed {args.seed}: expected a whole number from 0 to {2**32 - 1} (a random generator seed)")
    jobs = available_cores() if args.jobs is None else args.jobs
    if jobs < 1:
        raise InputError(f"--jobs {jobs}: expected a positive number of worker processes")
    cfg = plant_from_args(args, fallback="plant-a")
    library = _names(args.library, "--library")
    if args.practice:
        def row_done(row):
            mark = "OK " if row["correct"] else ("AMB" if row.get("ambiguous_with_truth") else "BAD")
            print(f"{mark} {row['name']:32s} truth {row['truth']:18s} -> {row['verdict']:16s} {row['winner'] or '-':28s} "
                  f"{row['seconds']:5.1f} s  {row['parameters']}", flush=True)

        rep = run_practice(args.practice, cfg, library=library, jobs=jobs, progress=row_done, scheduler=scheduler)
        amb = sum(bool(r.get("ambiguous_with_truth")) for r in rep["recordings"])
        print(f"\n{rep['correct']}/{len(rep['recordings'])} practice recordings diagnosed correctly"
              + (f"; {amb} more called ambiguous with the truth among the explanations named" if amb else ""))
        print(f"main parameter within 25 %: {rep['main_within_25']} of {rep['main_scored']}"
              + (f"; not a hit but not identifiable by the test (split interval contains the truth): "
                 f"{rep['main_split_open_interval_contains_truth']}" if rep["main_split_open_interval_contains_truth"] else ""))
        from compliance.diagnosis.scoring.practice_score import practice_markdown, practice_table

        print("\n" + practice_table(rep))
        _write(args, rep, practice_markdown)
        return 0 if rep["correct"] == len(rep["recordings"]) else 1

    from compliance.cli.progress import progress as progress_bar

    with progress_bar(None, "diagnose-benchmark", quiet=args.quiet, unit="case") as bar:
        def progress(r):
            mark = "OK " if r.correct else ("AMB" if r.ambiguous_with_truth else "BAD")
            err = "" if r.main_error is None else f" main-parameter error {100*r.main_error:.1f} %"
            if not args.quiet:
                print(f"{mark} {r.kind:14s} {r.truth:28s} -> {r.predicted:28s} {r.seconds:5.1f} s{err}", flush=True)
            bar.update(1)

        rep = run_benchmark(cfg, effects=_names(args.effects, "--effects"), cases=args.cases, seed=args.seed, library=library,
                            jobs=jobs, null=not args.no_null, miscalibrations=not args.no_miscalibrations, progress=progress,
                            scheduler=scheduler)
    print()
    print(format_summary(rep))
    from compliance.diagnosis.scoring.practice_score import benchmark_markdown

    _write(args, rep, benchmark_markdown)
    s = rep["summary"]
    ok = (s["top1_accuracy"] is None or s["top1_accuracy"] >= TOP1_TARGET) and (s["null_accuracy"] is None or s["null_accuracy"] >= NULL_TARGET)
    return 0 if ok else 1

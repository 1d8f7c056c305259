"""The one CLI convention, shared by every sub-command.

- The plant configuration is positional (a TOML path or a reference name such as ``plant-a``).
  ``--plant`` is still read for old scripts, but giving both is an error, never a silent choice.
- The same output options everywhere: ``--json FILE.json``, ``--junit FILE.xml``,
  ``--report FILE.html``, ``--pdf FILE.pdf``; the same ``--quiet/-q``, ``--jobs/-j`` and
  ``--reproducible``; ``--scheduler ADDR`` wherever work runs in parallel.
- Every output path is checked (folder, writability, suffix) before any work starts
  (:func:`compliance.files.outputs.check_outputs`).
"""

from __future__ import annotations

import argparse
import os
import re
from pathlib import Path

from compliance.errors import InputError
from compliance.units import parse_quantity

OUTPUT_SUFFIXES = {"json": (".json",), "junit": (".xml",), "report": (".html", ".htm"), "pdf": (".pdf",)}
_OUTPUT_HELP = {
    "json": "write the results as JSON to FILE.json",
    "junit": "write JUnit XML for CI to FILE.xml",
    "report": "write the HTML report to FILE.html",
    "pdf": "write the PDF report to FILE.pdf",
}
_METAVAR = {"json": "FILE.json", "junit": "FILE.xml", "report": "FILE.html", "pdf": "FILE.pdf"}


class GovcheckParser(argparse.ArgumentParser):
    """An argument parser that reads a word starting with a minus and a digit as a value, never an option.

    argparse takes only plain negative numbers (``-5``, ``-0.5``) as values; ``--steps -5%@1s``,
    ``--x0 -1mm`` or ``--load -1e3`` would be refused as unknown options. No govcheck option
    starts with a digit, so every such word is a (negative) quantity. Sub-command parsers
    inherit the class (``add_subparsers`` uses the parent's class).
    """

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-\.?\d")  # argparse's hook for "a negative number"


def wrap_description(text: str) -> str:
    """Paragraphs of ``text`` filled to 90 columns (the help keeps line breaks verbatim for the examples)."""
    import textwrap

    return "\n\n".join(textwrap.fill(" ".join(par.split()), 90, break_on_hyphens=False) for par in text.split("\n\n"))


def add_parser(sub, name: str, *, help: str, description: str, examples: list[str], usage: str | None = None):
    """A sub-command parser with its description (wrapped per paragraph) and an ``examples:`` epilog (kept verbatim)."""
    return sub.add_parser(
        name, help=help, description=wrap_description(description), usage=usage,
        epilog="examples:\n" + "\n".join(f"  {e}" for e in examples),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )


def add_plant_argument(parser, *, help: str | None = None) -> None:
    """The positional plant configuration (and the old ``--plant`` spelling, hidden).

    Optional for argparse so the old spelling still parses; :func:`plant_source` says when none is given.
    """
    parser.add_argument("config", metavar="CONFIG", nargs="?",
                        help=help or "plant configuration: a TOML file (models/plant-a.toml) or a reference name (plant-a)")
    parser.add_argument("--plant", help=argparse.SUPPRESS)


def plant_source(args, fallback: str | None = None, where: str = "") -> str:
    """The configuration named on the command line (positional or the old ``--plant``), else ``fallback``.

    Raises
    ------
    InputError
        Both spellings name different configurations, or none is given and there is no fallback.
    """
    pos, old = getattr(args, "config", None), getattr(args, "plant", None)
    if pos and old and os.path.normpath(pos) != os.path.normpath(old):
        raise InputError(f"two plant configurations given: '{pos}' and --plant '{old}'; give one (positional CONFIG)")
    src = pos or old or fallback
    if not src:
        raise InputError(f"{where + ': ' if where else ''}no plant configuration given: pass CONFIG "
                         "(a TOML file such as models/plant-a.toml, or a reference name such as plant-a)")
    return src


def plant_from_args(args, fallback: str | None = None, where: str = ""):
    """Load the plant named by :func:`plant_source`."""
    from compliance.model.config import load_plant

    return load_plant(plant_source(args, fallback, where))


def add_outputs(parser, *names: str, help: dict | None = None) -> None:
    """Add the standard output options ``--json/--junit/--report/--pdf`` (those named)."""
    for name in names:
        text = (help or {}).get(name, _OUTPUT_HELP[name])
        parser.add_argument(f"--{name}", metavar=_METAVAR[name], default=None, help=text)


def add_recording_inputs(parser, recordings: str) -> None:
    """``[CONFIG] RECORDING``, the hidden old ``--plant`` and ``--column-map`` (validate, diagnose)."""
    parser.add_argument("inputs", nargs="+", metavar="[CONFIG] RECORDING",
                        help="plant configuration (TOML file or reference name; default: the sidecar's 'plant') and "
                             + recordings)
    parser.add_argument("--plant", help=argparse.SUPPRESS)
    parser.add_argument("--column-map", help="column map (TOML path or shipped name) for a logger's own names and units")


def add_jobs(parser, what: str = "worker processes") -> None:
    """``--jobs/-j N``."""
    parser.add_argument("--jobs", "-j", type=int, default=None, metavar="N", help=f"{what} (default: the available cores)")


def add_scheduler(parser, what: str = "the parallel work") -> None:
    """``--scheduler ADDR``: run ``what`` on Dask instead of the local process pool (the one spelling, every command)."""
    parser.add_argument("--scheduler", metavar="ADDR",
                        help=f"run {what} on Dask: tcp://host:8786 for a running cluster, local:N to start a "
                             "LocalCluster of N workers; default: the local process pool (--jobs)")


def check_scheduler(args) -> str | None:
    """The ``--scheduler`` given, checked before any work (a bad or unreachable address is exit 2); None for the local pool."""
    from compliance.processes.dask_cluster import check_reachable

    value = getattr(args, "scheduler", None)
    check_reachable(value)
    return value


def add_quiet(parser, what: str = "no progress; print only the verdict line") -> None:
    """``--quiet/-q``."""
    parser.add_argument("--quiet", "-q", action="store_true", help=what)


def add_reproducible(parser) -> None:
    """``--reproducible``: byte-identical outputs (also switched on by SOURCE_DATE_EPOCH)."""
    parser.add_argument("--reproducible", action="store_true",
                        help="byte-identical output files across runs: fixed 'created' (SOURCE_DATE_EPOCH, else "
                             "1970-01-01), no timings (also on when SOURCE_DATE_EPOCH is set)")


def add_document_options(parser) -> None:
    """``--document-number`` / ``--revision``: the report's document control (over the configuration's ``[identity]``)."""
    parser.add_argument("--document-number", metavar="TEXT",
                        help="document number printed on the report (else [identity] document_number; without one the "
                             "report is marked DRAFT)")
    parser.add_argument("--revision", metavar="TEXT", help="revision of the report (else [identity] revision)")


def check_document_options(args) -> None:
    """``--document-number`` / ``--revision`` are printed on a report: without --report or --pdf they would go nowhere."""
    if getattr(args, "report", None) or getattr(args, "pdf", None):
        return
    for flag, value in (("--document-number", getattr(args, "document_number", None)),
                        ("--revision", getattr(args, "revision", None))):
        if value is not None:
            raise InputError(f"{flag} {value}: is printed on the report, and no report is asked for; add --report FILE.html "
                             "or --pdf FILE.pdf")


def document_options(args, results_path=None, results_text: str | None = None) -> dict:
    """The ``document`` argument of the report renderers: number, revision and the results file's sha256."""
    import hashlib

    from compliance.files.display import display_path

    doc = {"number": getattr(args, "document_number", None), "revision": getattr(args, "revision", None)}
    if results_path is not None:
        data = results_text.encode("utf-8") if results_text is not None else Path(results_path).read_bytes()
        doc["results"] = {"path": display_path(str(results_path)), "digest": hashlib.sha256(data).hexdigest()}
    return doc


def add_allow_conflicts(parser) -> None:
    """``--allow-conflicts``: judge a requirement set whose mandatory limits cannot hold together (every command that loads one)."""
    parser.add_argument("--allow-conflicts", action="store_true",
                        help="judge a requirement set even when two mandatory limits cannot hold together (without it such a set "
                             "is refused with exit code 2 before any simulation; docs/requirements.md)")


def checked_requirements(source, strokes, args):
    """Load the requirement set ``source`` and vet it for every stroke [m] of ``strokes`` (before any work).

    For a command whose plant is not known before its work starts (``size``, ``sweep``, ``accept``);
    the vetting is the one a check runs (``compliance.requirements.vetting.vet``, as
    ``compliance.pipeline.chain.Check.of``): a loosened limit, or a conflict between mandatory limits
    unless ``--allow-conflicts``, is exit 2.
    """
    from compliance.requirements.loading import load_requirements
    from compliance.requirements.vetting import vet

    reqset = source if hasattr(source, "requirements") else load_requirements(source)
    allow = bool(getattr(args, "allow_conflicts", False))
    for stroke in dict.fromkeys(strokes):
        vet(reqset, stroke, allow)
    return reqset


def check_jobs(args) -> None:
    """``--jobs`` must be a positive count."""
    jobs = getattr(args, "jobs", None)
    if jobs is not None and jobs < 1:
        raise InputError(f"--jobs {jobs}: expected a positive number of processes")


def standard_outputs(args, *extra) -> list:
    """``(path, flag, suffixes)`` of the standard outputs set in ``args``, plus ``extra`` ones."""
    out = []
    for name, suffixes in OUTPUT_SUFFIXES.items():
        path = getattr(args, name, None)
        if isinstance(path, str):
            out.append((path, f"--{name}", suffixes))
    return out + [e for e in extra if e[0] is not None]


def check_args_outputs(args, *extra, inputs: dict | None = None) -> None:
    """Check ``--jobs`` and every output path before any work (nothing written on failure).

    Every other argument that names an existing file is an input, and no output may be one of them;
    ``inputs`` (``{path: what it is}``) adds files the run reads that no argument names (a duty's template).
    """
    from compliance.files.outputs import check_outputs

    from compliance.files.reproducible import fixed_created, is_reproducible

    check_jobs(args)
    check_document_options(args)
    if is_reproducible(getattr(args, "reproducible", False)):
        fixed_created()  # a bad SOURCE_DATE_EPOCH is refused now, not after the work
    outputs = standard_outputs(args, *extra)
    if getattr(args, "reproducible", False) is True and not outputs:
        raise InputError("--reproducible: makes the files a run writes byte-identical, and this run writes none; add an "
                         "output (--json FILE.json, ...) or drop --reproducible")
    found = input_files(args, {o[1].split("/")[-1].lstrip("-").replace("-", "_") for o in outputs})
    check_outputs(*outputs, inputs={**(inputs or {}), **found})


_POSITIONAL = {"config": "CONFIG", "inputs": "[CONFIG] RECORDING", "recordings": "RECORDING", "sweep": "SWEEP",
               "results": "RESULTS", "candidate_pos": "CANDIDATE"}


def input_files(args, output_names: set) -> dict:
    """``{path: "--flag"}`` of every argument (not an output option) that names an existing file."""
    found = {}
    for name, value in vars(args).items():
        if name.startswith("_") or name in output_names or name in OUTPUT_SUFFIXES:
            continue
        for item in value if isinstance(value, list) else [value]:
            if isinstance(item, str) and item and os.path.isfile(item):
                found.setdefault(item, _POSITIONAL.get(name, f"--{name.replace('_', '-')}"))
    return found


def quantity(text: str | None, si_unit: str, option: str, default: float | None = None) -> float | None:
    """Parse a CLI quantity such as '136 mm' or '11.4 kN'; a bare number means SI."""
    if text is None:
        return default
    try:
        value = float(text)
    except ValueError:
        return parse_quantity(text, si_unit, option)
    if value != value or value in (float("inf"), float("-inf")):
        raise InputError(f"{option} {text!r}: expected a finite number")
    return value


def parse_param_overrides(items, option: str = "--param") -> dict:
    """``KEY=VALUE`` (SI) overrides, each checked against the parameter table's admissible range."""
    from compliance.errors import did_you_mean
    from compliance.model.parameters import BASE_BY_KEY

    out = {}
    for item in items:
        if "=" not in item:
            raise InputError(f"{option}: '{item}' must look like KEY=VALUE (SI), e.g. friction.bristle_stiffness=1e6")
        k, v = (s.strip() for s in item.split("=", 1))
        spec = BASE_BY_KEY.get(k)
        if spec is None:
            raise InputError(f"{option} {k}: not a plant parameter{did_you_mean(k, BASE_BY_KEY)}")
        try:
            value = float(v)
        except ValueError:
            raise InputError(f"{option} {k}: '{v}' is not a number (give SI units, {spec.unit or 'dimensionless'})") from None
        low, high = spec.bounds
        low_ok = value > low if spec.low_open else value >= low
        if not (low_ok and value <= high):
            bracket = "(" if spec.low_open else "["
            raise InputError(f"{option} {k}={v}: outside the admissible range {bracket}{low:g}, {high:g}] "
                             f"{spec.unit} ({spec.meaning})")
        out[k] = value
    return out


def looks_like_config(text: str) -> bool:
    """A plant configuration on the command line: a ``.toml`` file or a shipped reference name."""
    from compliance.files.shipped import shipped_names

    return text.lower().endswith(".toml") or text in shipped_names("plant")


def split_config(args, inputs: list[str], what: str = "RECORDING") -> tuple[str | None, list[str]]:
    """``[CONFIG] INPUT...`` -> (configuration or None, inputs); the old ``--plant`` is honoured.

    Raises
    ------
    InputError
        No input left, or two different configurations (positional and ``--plant``).
    """
    config = inputs[0] if len(inputs) > 1 and looks_like_config(inputs[0]) else None
    rest = inputs[1:] if config else list(inputs)
    if not rest:
        raise InputError(f"no {what} given: the arguments are [CONFIG] {what}")
    for item in rest:
        if looks_like_config(item):
            raise InputError(f"{item}: a plant configuration in the place of a {what}; the order is [CONFIG] {what}")
    args.config = config
    return plant_source(args, fallback="", where="") if (config or getattr(args, "plant", None)) else None, rest


def sidecar_plant(meta: dict, recording) -> str | None:
    """The sidecar's ``plant``: a reference name, or a file path taken relative to the recording's folder."""
    from pathlib import Path

    src = meta.get("plant")
    if not isinstance(src, str) or not src.strip():
        return None
    if looks_like_config(src) and src.lower().endswith(".toml"):
        p = Path(src)
        if not p.is_absolute():
            from compliance.recordings.metadata import sidecar_path

            beside = sidecar_path(recording).parent / p
            if beside.is_file() or not p.is_file():
                return str(beside)
    return src


def check_sidecar_conditions(cfg, frame, meta: dict, recording) -> None:
    """The recording and its sidecar are possible for this plant (``recordings.against_plant``), before any replay."""
    from compliance.recordings.against_plant import check_against_plant

    check_against_plant(cfg, frame, meta, recording)

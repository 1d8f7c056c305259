"""govcheck command line: a thin dispatcher.

Each sub-command lives in its own module under ``compliance.cli`` with two functions,
``register(subparsers)`` and ``run(args) -> int``. Exit codes: 0 pass, 1 a requirement
failed (or a gate tripped), 2 invalid input or a solver failure.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys

from compliance.errors import GovcheckError

# command name -> module; the order is the order shown by --help
_COMMANDS = (
    ("plants", "plants"),
    ("simulate", "simulate"),
    ("reproduce", "reproduce"),
    ("check", "check"),
    ("accept", "accept"),
    ("gate", "gate"),
    ("sweep", "sweep"),
    ("size", "size"),
    ("report", "report"),
    ("linear", "linear"),
    ("validate", "validate"),
    ("characterise", "characterise"),
    ("diagnose", "diagnose"),
    ("diagnose-benchmark", "diagnose_benchmark"),
)


def build_parser() -> argparse.ArgumentParser:
    """Build the argument parser with every available sub-command."""
    from compliance.version import __version__
    from compliance.cli.common import GovcheckParser

    parser = GovcheckParser(
        prog="govcheck",
        description=(
            "Acceptance harness for pneumatic gate servo-positioners of hydro-turbine speed "
            "governors: simulate, check against IEC 61362 / IEEE 125 requirement files, "
            "linearise, validate against recordings and diagnose missing physics."
        ),
        epilog=_EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"govcheck {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    handlers = {}
    for name, module in _COMMANDS:
        try:
            mod = importlib.import_module(f"{__name__}.{module}")
        except ModuleNotFoundError as exc:
            if exc.name == f"{__name__}.{module}":
                continue  # command not built yet
            raise
        p = mod.register(sub)
        p.set_defaults(_run=mod.run)
        handlers[name] = mod
    return parser


def _silence_stdout() -> None:
    """Point stdout at /dev/null so the interpreter's last flush does not fail on the closed pipe again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):  # no real stdout (captured in tests): nothing to redirect
        pass


_EXAMPLES = """examples:
  govcheck check models/plant-a.toml -r requirements/shpp-400kw.toml --json r.json --report r.html
  govcheck accept site-folder -r shpp-400kw --json s.json --report s.html   (a site's commissioning recordings)
  govcheck simulate plant-a --steps '2%@1s,-2%@4s' -o run.csv --plot run.png
  govcheck validate run.csv --report v.html        (the sidecar run.toml names the plant)
  govcheck diagnose rec.csv.gz --json d.json --save-model fitted.toml
  govcheck gate models/candidate.toml --baseline r.json --markdown pr-comment.md
  govcheck COMMAND --help                          (each command's options and examples)

Exit codes: 0 all pass, 1 a requirement failed (or a gate tripped), 2 invalid input, 3 an internal error."""


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``govcheck`` console script.

    The signal handling is set first, before the command modules (and numpy, numba, pandas...) are
    imported: a Ctrl-C or SIGTERM at any moment from here on ends the run with one line and exit
    130 / 143, never a KeyboardInterrupt traceback.
    """
    from compliance.processes.stopping import stop_on_signals

    stop_on_signals()  # SIGTERM unwinds like Ctrl-C: workers killed, temporary files removed, exit 143 (Ctrl-C 130)
    command = None
    try:
        parser = build_parser()
        try:
            args = parser.parse_args(argv)
        except SystemExit as exc:  # argparse: usage error (2) or --help/--version (0)
            return int(exc.code or 0) if not isinstance(exc.code, str) else 2
        command = getattr(args, "command", None)
        if not command:
            parser.print_help(sys.stderr)
            print("govcheck: error: no COMMAND given; choose one of the commands above (govcheck COMMAND --help)",
                  file=sys.stderr)
            return 2
        code = _run(args)
        if argv is None:  # the govcheck command itself (tests pass argv): a signal after the run cannot change its end
            from compliance.processes.stopping import ignore_late_signals

            ignore_late_signals()
        return code
    except KeyboardInterrupt as exc:  # while starting (imports, parsing) or between the run's end and its exit
        return _interrupted(command, exc)


def _interrupted(command: str | None, exc: KeyboardInterrupt) -> int:
    from compliance.processes.stopping import Terminated

    term = isinstance(exc, Terminated)
    print(f"govcheck{' ' + command if command else ''}: {'terminated' if term else 'interrupted'}; nothing more written",
          file=sys.stderr)
    return 143 if term else 130


def _check_source_date_epoch() -> None:
    """A malformed ``SOURCE_DATE_EPOCH`` is refused before any command module loads (numpy reads it on import too)."""
    import os

    if os.environ.get("SOURCE_DATE_EPOCH", "").strip():
        from compliance.files.reproducible import fixed_created

        fixed_created()


def _run(args) -> int:
    """Run the parsed command; map every way it can end to an exit code and one line on stderr."""
    from compliance.processes import raise_if_stopping

    try:
        _check_source_date_epoch()
        code = args._run(args)
        sys.stdout.flush()  # inside the try: a reader that went away is met here, not at the interpreter's exit
        raise_if_stopping()  # a signal whose exception Python swallowed (in a fork hook) still ends as interrupted
    except GovcheckError as exc:
        print(f"govcheck {args.command}: error: {exc}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt as exc:
        return _interrupted(args.command, exc)
    except BrokenPipeError:  # the reader went away (govcheck linear ... | head -n 1): stop quietly, as cat does
        _silence_stdout()
        return 141
    except OSError as exc:  # a file the checks could not foresee (disk full, removed meanwhile)
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"govcheck {args.command}: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
    except Exception as exc:  # a bug: one line, never exit 1 (which CI reads as a failed requirement)
        if os.environ.get("GOVCHECK_DEBUG"):
            raise
        print(f"govcheck {args.command}: internal error: {type(exc).__name__}: {exc} "
              "(a bug in govcheck; set GOVCHECK_DEBUG=1 for the traceback and please report it)", file=sys.stderr)
        return 3
    return int(code or 0)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

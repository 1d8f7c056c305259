"""The remedies options of ``govcheck check``: catalogue, yield units, scheduler, resumable state, saved remedy."""

from __future__ import annotations

import sys

from compliance.cli.common import add_scheduler, check_scheduler
from compliance.errors import InputError

__all__ = ["add_remedies_options", "check_remedies_options", "remedies_kwargs", "save_remedy"]


def add_remedies_options(p) -> None:
    """Add the options that shape ``--remedies``."""
    p.add_argument("--save-remedy", metavar="FILE.toml",
                   help="with --remedies: write the verified remedy as a configuration file that govcheck check accepts "
                        "(written only when a remedy is found)")
    p.add_argument("--catalogue", metavar="FILE.toml", default="default",
                   help="with --remedies: hardware catalogue of orderable options (default: the shipped "
                        "models/hardware-catalogue.toml; 'none' for settings only)")
    p.add_argument("--yield-units", type=int, default=None, metavar="N",
                   help="with --remedies: Monte Carlo units of the remedy's tolerance yield (default 59: 59/59 passing shows "
                        ">= 95 %% at 95 %% confidence; 0 skips it)")
    add_scheduler(p, "the --remedies search (needs --remedies)")
    p.add_argument("--remedies-state", metavar="DIR",
                   help="with --remedies: keep every judged candidate in DIR so an interrupted search resumes there")


def check_remedies_options(args) -> None:
    """Refuse inconsistent or bad remedies options before any work (exit 2)."""
    used = [f for f in ("save_remedy", "yield_units", "scheduler", "remedies_state") if getattr(args, f, None) is not None]
    if used and not args.remedies:
        raise InputError(f"--{used[0].replace('_', '-')} needs --remedies")
    if args.yield_units is not None and args.yield_units < 0:
        raise InputError(f"--yield-units {args.yield_units}: expected 0 or a positive number of units")
    check_scheduler(args)
    if args.remedies and args.catalogue not in ("default", "none"):
        from compliance.sweep.hardware import load_catalogue

        load_catalogue(args.catalogue)  # a bad catalogue is exit 2 before any simulation


def remedies_kwargs(args) -> dict:
    """Keyword arguments of ``remedies_for_check`` from the options."""
    from compliance.sweep.candidate_store import CandidateStore
    from compliance.sweep.check_remedies import YIELD_UNITS

    return {"catalogue": None if args.catalogue == "none" else args.catalogue, "scheduler": args.scheduler,
            "yield_units": YIELD_UNITS if args.yield_units is None else args.yield_units,
            "store": CandidateStore(args.remedies_state) if args.remedies_state else None}


def save_remedy(args, cfg, rem) -> None:
    """Write the remedy configuration (``--save-remedy``) when one was found; say so either way."""
    if not args.save_remedy:
        return
    if rem.get("status") != "found":
        print(f"--save-remedy {args.save_remedy}: nothing written (no verified remedy in the declared space)", file=sys.stderr)
        return
    from compliance.model.config import save_plant
    from compliance.sweep.parameter_paths import describe
    from compliance.sweep.remedy_finish import remedy_configuration, remedy_values

    paths = {p: describe(p, "remedy") for p in remedy_values(rem)}
    save_plant(remedy_configuration(cfg, rem, paths), args.save_remedy, overwrite=True)
    if not args.quiet:
        print(f"remedy written to {args.save_remedy} (govcheck check {args.save_remedy} -r {args.requirements})")

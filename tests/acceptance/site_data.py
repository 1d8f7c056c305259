"""The reduced practice site p2 of tests/data/acceptance/ (provenance in tests/data/README.md) and its truth."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

DATA = Path(__file__).resolve().parents[1] / "data" / "acceptance"
SITE = DATA / "site-p2"
TRUTH = json.loads((DATA / "truth-site-p2.json").read_text())


def truth(name: str) -> dict:
    """The emulator's noise-free figures of one recording of the fixture site."""
    return TRUTH["tests"][name]["truth"]


def copy_site(dest: Path, names=None) -> Path:
    """A copy of the fixture site (or of the named recordings of it) in ``dest``, to spoil."""
    dest.mkdir(parents=True, exist_ok=True)
    for p in sorted(SITE.iterdir()):
        stem = p.name.split(".")[0]
        if names is None or stem in names:
            shutil.copyfile(p, dest / p.name)
    return dest

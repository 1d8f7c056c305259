"""File paths as a reader of a report should see them: relative to the working folder, or the
reference name for files shipped inside the package (never an installation's absolute path)."""

from __future__ import annotations

import os
from pathlib import Path


def display_path(path: str | None) -> str | None:
    """``models/plant-a.toml`` for a file under the working folder; ``plant-a (reference, govcheck x.y)``
    for a shipped reference file; else the path unchanged."""
    if not path:
        return path
    p = Path(path).resolve()
    package = Path(__file__).resolve().parent.parent / "data"
    try:
        rel = p.relative_to(package)
        from compliance.version import __version__

        return f"{rel.stem} (reference {rel.parts[0][:-1]}, govcheck {__version__})"
    except ValueError:
        pass
    try:
        return os.path.relpath(p, Path.cwd()) if p.is_relative_to(Path.cwd()) else str(path)
    except ValueError:
        return str(path)

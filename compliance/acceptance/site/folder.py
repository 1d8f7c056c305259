"""A site: a folder of commissioning recordings of one machine, each test its own recording with its sidecar.

Every recording the readers know is read (``recordings.reader.read_recording``: canonical CSV,
``.csv.gz``, column-mapped text, ``.mat``, COMTRADE ``.cfg``/``.cff``, Parquet), with its sidecar's
``[test]`` table as the test as run (``site.stated``); a recording the sidecar does not describe
gets its kind from its trace (``site.recognise``). Everything is read and checked before any
figure is taken: a bad file stops the run with one message naming it.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from compliance.errors import InputError
from compliance.recordings.reader import read_recording

__all__ = ["RECORDING_SUFFIXES", "SiteRecording", "read_site", "recording_name", "site_plant"]

RECORDING_SUFFIXES = (".csv", ".csv.gz", ".txt", ".txt.gz", ".tsv", ".mat", ".cfg", ".cff", ".parquet", ".pq")


@dataclass
class SiteRecording:
    """One recording of a site: its name, file, canonical frame and metadata (``read_recording``)."""

    name: str
    path: Path
    frame: object
    meta: dict


def recording_name(path: Path) -> str:
    """A recording's name: its file name without the recording suffix (``steps_1.csv.gz`` -> ``steps_1``)."""
    low = path.name.lower()
    for suffix in sorted(RECORDING_SUFFIXES, key=len, reverse=True):
        if low.endswith(suffix):
            return path.name[: -len(suffix)]
    return path.stem


def _recordings(folder: Path) -> list[Path]:
    files = [p for p in sorted(folder.iterdir()) if p.is_file() and p.name.lower().endswith(RECORDING_SUFFIXES)]
    names: dict = {}
    for p in files:
        names.setdefault(recording_name(p), []).append(p)
    twice = {n: ps for n, ps in names.items() if len(ps) > 1}
    if twice:
        n, ps = next(iter(twice.items()))
        raise InputError(f"{folder}: recording '{n}' is there twice ({', '.join(p.name for p in ps)}); keep one file per test")
    return files


def read_site(folder, column_map=None) -> list[SiteRecording]:
    """Read every recording of a site folder.

    Parameters
    ----------
    folder : str or pathlib.Path
        The site: a folder of recordings, each with its ``NAME.toml`` sidecar.
    column_map : optional
        A column map for recordings in a logger's own names and units (``recordings.column_map``).

    Raises
    ------
    InputError
        Not a folder, no recording in it, a recording twice, or a recording a reader rejects
        (the reader's message names the file, row or column).
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(f"{folder}: not a folder; a site is a folder of recordings (one per test, each with its NAME.toml sidecar)")
    files = _recordings(folder)
    if not files:
        raise InputError(f"{folder}: no recording found; expected files ending in {', '.join(RECORDING_SUFFIXES)}")
    out = []
    for path in files:
        frame, meta = read_recording(path, column_map)
        out.append(SiteRecording(recording_name(path), path, frame, meta))
    return out


def site_plant(recordings: list[SiteRecording]) -> tuple[str | None, Path | None]:
    """The plant every sidecar names (as written) and the recording that names it first, or (None, None).

    Raises
    ------
    InputError
        Two sidecars name different plants: a site is one machine.
    """
    named = [(r.meta.get("plant"), r.path) for r in recordings if isinstance(r.meta.get("plant"), str) and r.meta["plant"].strip()]
    if not named:
        return None, None
    first, where = named[0]
    for plant, path in named[1:]:
        if plant.strip() != first.strip():
            raise InputError(f"{path}: plant '{plant}' where {where.name} says '{first}'; a site is one machine "
                             "(give CONFIG to judge them against one plant model)")
    return first.strip(), where

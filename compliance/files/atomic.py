"""The one atomic writer: a temporary file in the target folder, then ``os.replace``.

A reader (a CI job, a browser, the next govcheck run) never sees half a file, and a failed
write leaves the previous good file in place. Every file govcheck writes gets the same
permissions (``0666`` minus the umask, as ``open()`` would give), whatever wrote its bytes.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Callable

from compliance.processes import raise_if_stopping
from compliance.files.jsonable import json_text

__all__ = ["file_bytes", "write_atomic_with", "write_bytes_atomic", "write_json_atomic", "write_text_atomic"]


def _usual_mode() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


def write_atomic_with(path, write: Callable[[str], None]) -> None:
    """Let ``write(tmp_path)`` produce the file, then move it onto ``path`` atomically.

    For writers that want a file name (pandas, pyarrow, matplotlib). The temporary file keeps
    the target's suffix so suffix-sniffing writers pick the right format.

    Raises
    ------
    InputError
        The folder does not exist or the target is read-only / a folder (nothing is written).
    """
    from compliance.files.outputs import check_output

    path = Path(path)
    check_output(path, "output")
    folder = path.parent if str(path.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=f".tmp{path.suffix}", dir=folder)
    os.close(fd)
    try:
        write(tmp)
        os.chmod(tmp, _usual_mode())  # mkstemp makes 0600; give the file the usual permissions
        raise_if_stopping()  # a stop whose exception was swallowed still writes nothing
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def write_bytes_atomic(path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically."""
    def _write(tmp: str) -> None:
        with open(tmp, "wb") as fh:
            fh.write(data)

    write_atomic_with(path, _write)


def file_bytes(path, text: str) -> bytes:
    """``text`` as the bytes of the file ``path`` names: UTF-8, gzip-compressed when it ends in ``.gz``.

    The gzip header carries no time stamp (mtime 0): the same text gives the same bytes.
    """
    data = text.encode("utf-8")
    if str(path).lower().endswith(".gz"):
        import gzip

        return gzip.compress(data, mtime=0)
    return data


def write_text_atomic(path, text: str) -> None:
    """Write ``text`` to ``path`` atomically (temp file in the same folder + os.replace): UTF-8, compressed
    when ``path`` ends in ``.gz`` (:func:`file_bytes`)."""
    write_bytes_atomic(path, file_bytes(path, text))


def write_json_atomic(path, data, *, compact: bool = False) -> None:
    """Write ``data`` as strict JSON (cleaned by the one JSON cleaner) to ``path`` atomically."""
    write_text_atomic(path, json_text(data, compact=compact))

"""Progress for the commands: a tqdm bar on a terminal, periodic one-line updates in a CI log.

On a terminal tqdm redraws one line; when stderr is a file or a pipe (CI), every update is
a complete line of its own, at most one every ``LOG_INTERVAL`` seconds plus the first and the
last, so a log shows that something is happening without filling up.
"""

from __future__ import annotations

import sys

LOG_INTERVAL = 10.0  # [s] between lines when stderr is not a terminal


class _LineWriter:
    """A file for tqdm that turns its carriage-return redraws into whole lines."""

    def __init__(self, stream):
        self.stream = stream

    def write(self, text: str) -> None:
        text = text.replace("\r", "").replace("\x1b[A", "").strip()
        if text:
            self.stream.write(text + "\n")

    def flush(self) -> None:
        self.stream.flush()


def progress(total: int, desc: str, *, quiet: bool = False, unit: str = "step"):
    """A tqdm progress bar on stderr (disabled when ``quiet``).

    Use as a context manager; call ``.update(1)`` per item and ``.set_postfix_str(text)`` for
    the item's name.
    """
    from tqdm import tqdm

    tty = hasattr(sys.stderr, "isatty") and sys.stderr.isatty()
    return tqdm(
        total=total, desc=desc, unit=unit, disable=quiet, leave=tty,
        file=sys.stderr if tty else _LineWriter(sys.stderr),
        mininterval=0.1 if tty else LOG_INTERVAL, maxinterval=LOG_INTERVAL if not tty else 10.0,
        ascii=not tty, dynamic_ncols=tty, ncols=None if tty else 100,
    )

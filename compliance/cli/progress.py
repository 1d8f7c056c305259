"""Progress for the commands: a tqdm bar on a terminal, periodic one-line updates in a CI log.

On a terminal tqdm redraws one line; when stderr is a file or a pipe (CI), every update is a
complete line of its own, at most one every ``LOG_INTERVAL`` seconds plus the first and the
last, and a long stage without updates still prints its elapsed time every ``LOG_INTERVAL``
seconds, so a CI log shows that something is happening without filling up.
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading

LOG_INTERVAL = 10.0  # [s] between lines when stderr is not a terminal

# The heartbeat thread writes while worker processes may be forked (campaign, diagnosis): a fork
# never happens in the middle of its write, so no child inherits a held stderr or tqdm lock.
_WRITING = threading.Lock()
if hasattr(os, "register_at_fork"):
    os.register_at_fork(before=_WRITING.acquire, after_in_parent=_WRITING.release, after_in_child=_WRITING.release)


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


def _heartbeat(bar, stop: threading.Event) -> None:
    while not stop.wait(LOG_INTERVAL):
        with _WRITING:
            bar.refresh()  # one line with the elapsed time, even while a single stage runs


@contextlib.contextmanager
def progress(total: int | None, desc: str, *, quiet: bool = False, unit: str = "step", heartbeat: bool = True,
             first: str | None = None):
    """A tqdm progress bar on stderr (disabled when ``quiet``), as a context manager.

    Call ``.update(1)`` per item and ``.set_postfix_str(text, refresh=False)`` for the next item's name
    (``first`` names the first one, shown on the opening line). ``heartbeat``
    (not on a terminal): a line with the elapsed time every ``LOG_INTERVAL`` seconds even without
    updates; switch it off where the work itself reports per item.
    """
    from tqdm import tqdm

    tty = hasattr(sys.stderr, "isatty") and sys.stderr.isatty()
    bar = tqdm(
        total=total, desc=desc, unit=unit, disable=quiet, leave=True, postfix=first,
        file=sys.stderr if tty else _LineWriter(sys.stderr),
        mininterval=0.1 if tty else LOG_INTERVAL, maxinterval=LOG_INTERVAL,
        ascii=not tty, dynamic_ncols=tty, ncols=None if tty else 100,
    )
    stop = threading.Event()
    beat = None
    if heartbeat and not tty and not quiet and LOG_INTERVAL > 0:
        beat = threading.Thread(target=_heartbeat, args=(bar, stop), daemon=True)
        beat.start()
    try:
        yield bar
    finally:
        stop.set()
        if beat is not None:
            beat.join()
        bar.close()

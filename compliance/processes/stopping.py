"""Worker processes that stop with the run: the one process pool (`worker_pool`) and the signal handling.

The executor (:mod:`compliance.processes.executor`) runs every local parallel stage on a
:func:`worker_pool`. Its workers ignore SIGINT and SIGTERM's Python
handler (a Ctrl-C on a terminal reaches the whole process group; only the parent decides), and
when the parent leaves the pool through an exception - KeyboardInterrupt from SIGINT, or
:class:`Terminated` from SIGTERM (see :func:`stop_on_signals`) - every worker is killed at once
and the queued tasks are dropped, instead of the pool's normal exit that waits for all of them.
No worker is left holding the terminal's or a pipe's stdout (``govcheck check | tee log``).

Python may swallow an exception raised by a signal handler (one that lands in a finaliser or
in a fork hook is only printed as "Exception ignored"), so the handler also arms a watchdog:
if the process is still alive ``GRACE`` seconds later, it kills the worker processes and exits
with the signal's code. The normal unwinding (temporary files removed, workers killed) takes
well under that.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time
from contextlib import contextmanager

__all__ = ["GRACE", "Terminated", "ignore_late_signals", "raise_if_stopping", "stop_signal", "stop_on_signals",
           "worker_pool"]

GRACE = 3.0  # [s] after a signal, the unwinding's budget before the watchdog ends the process (the issue asks <= 5 s)
_ARMED = threading.Event()
_SIGNAL: list = []  # the signal received, once one has been


class Terminated(KeyboardInterrupt):
    """SIGTERM received: unwinds like Ctrl-C (files in progress removed, workers killed)."""


def stop_signal() -> int | None:
    """The signal that asked this process to stop, or None."""
    return _SIGNAL[0] if _SIGNAL else None


def raise_if_stopping() -> None:
    """Raise the stop again if a signal came and its exception was swallowed (call before writing an output)."""
    if _SIGNAL:
        raise Terminated() if _SIGNAL[0] == signal.SIGTERM else KeyboardInterrupt()


def _on_signal(signum, frame):
    if not _SIGNAL:
        _SIGNAL.append(signum)
    if not _ARMED.is_set():
        _ARMED.set()
        threading.Thread(target=_watchdog, args=(signum,), name="govcheck-stop", daemon=True).start()
    raise Terminated() if signum == signal.SIGTERM else KeyboardInterrupt()


def _watchdog(signum) -> None:
    time.sleep(GRACE)
    import multiprocessing as mp

    for child in mp.active_children():
        child.kill()
    try:
        sys.stderr.write("govcheck: stopped by a signal\n")
        sys.stderr.flush()
    finally:
        os._exit(128 + int(signum))


def stop_on_signals() -> None:
    """SIGTERM unwinds the main process like SIGINT; both end it within ``GRACE`` s (call once, in the CLI's main thread).

    A SIGINT that the process inherited as ignored (a background job of a script) stays ignored.
    """
    if threading.current_thread() is not threading.main_thread():
        return  # only the main thread may set handlers (govcheck called from a thread: the caller's signals stay)
    signal.signal(signal.SIGTERM, _on_signal)
    if signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:
        signal.signal(signal.SIGINT, _on_signal)
    sys.unraisablehook = _quiet_stop(sys.unraisablehook)


def ignore_late_signals() -> None:
    """The run is over (its outputs written, its exit code decided): a SIGINT or SIGTERM from now on changes nothing.

    The interpreter's teardown puts Python-level handlers back to the default action, so a Ctrl-C
    landing there would kill the finished process with the signal instead of its exit code; an
    ignored signal stays ignored. Call it from the command-line entry only, never in a library caller.
    """
    if threading.current_thread() is not threading.main_thread() or _SIGNAL:
        return
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _quiet_stop(previous):
    """The stop swallowed by a fork hook or a finaliser is not a bug to print: it is re-raised later, quietly.

    So is CPython's own race at exit after a killed pool (3.11: ``concurrent.futures.process._python_exit``
    wakes each pool's management thread without its lock, and a thread that is closing that pipe at the same
    moment makes the write fail with EBADF): after a stop, that one error is the pool going away as asked.
    """
    def hook(unraisable):
        if _SIGNAL and (isinstance(unraisable.exc_value, KeyboardInterrupt) or _pool_exit_race(unraisable)):
            return
        previous(unraisable)

    return hook if getattr(previous, "__name__", "") != "hook" else previous


def _pool_exit_race(unraisable) -> bool:
    import errno
    import traceback

    exc = unraisable.exc_value
    if not (isinstance(exc, OSError) and exc.errno == errno.EBADF):
        return False
    frames = traceback.extract_tb(unraisable.exc_traceback) if unraisable.exc_traceback else []
    return any(f.filename.endswith(("concurrent/futures/process.py", "multiprocessing/connection.py")) for f in frames)


def _worker_init(initializer, initargs):
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent handles Ctrl-C and then kills us
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # a plain, silent death when the parent terminates us
    if initializer is not None:
        initializer(*initargs)


@contextmanager
def worker_pool(max_workers: int, mp_context=None, initializer=None, initargs=()):
    """A ``ProcessPoolExecutor`` whose workers die with the run (see the module docstring).

    Parameters
    ----------
    max_workers : int
        Worker processes.
    mp_context : multiprocessing context, optional
        Default: ``fork`` (the context is inherited, not pickled).
    initializer, initargs
        Run in each worker after its signals are set.
    """
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    ctx = mp_context or mp.get_context("fork")
    pool = ProcessPoolExecutor(max_workers=max_workers, mp_context=ctx, initializer=_worker_init,
                               initargs=(initializer, initargs))
    try:
        yield pool
    except BaseException:
        _kill(pool)
        raise
    else:
        pool.shutdown(wait=True)


def _kill(pool) -> None:
    procs = list((getattr(pool, "_processes", None) or {}).values())
    for p in procs:
        if p.is_alive():
            p.kill()
    queue = getattr(pool, "_call_queue", None)
    if queue is not None:  # tasks still in the pipe to the dead workers: never wait at exit to flush them
        queue.cancel_join_thread()
    pool.shutdown(wait=False, cancel_futures=True)
    for p in procs:
        p.join(timeout=2.0)
    # the pool's management thread closes its wake-up pipe as it ends; let it end now, so the interpreter's exit
    # hook does not write to that pipe while it is being closed (EBADF, CPython's race at exit)
    manager = getattr(pool, "_executor_manager_thread", None)
    if manager is not None and manager is not threading.current_thread():
        manager.join(timeout=1.0)

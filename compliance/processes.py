"""The one way govcheck starts worker processes, and stops them all when the run is interrupted.

Every process pool (campaign and sweep executor, diagnosis fits, benchmark, calibration, operating
maps, report figures) is a :func:`worker_pool`. Its workers ignore SIGINT and SIGTERM's Python
handler (a Ctrl-C on a terminal reaches the whole process group; only the parent decides), and
when the parent leaves the pool through an exception - KeyboardInterrupt from SIGINT, or
:class:`Terminated` from SIGTERM (see :func:`stop_on_sigterm`) - every worker is killed at once
and the queued tasks are dropped, instead of the pool's normal exit that waits for all of them.
No worker is left holding the terminal's or a pipe's stdout (``govcheck check | tee log``).
"""

from __future__ import annotations

import signal
from contextlib import contextmanager

__all__ = ["Terminated", "stop_on_sigterm", "worker_pool"]


class Terminated(KeyboardInterrupt):
    """SIGTERM received: unwinds like Ctrl-C (files in progress removed, workers killed)."""


def _raise_terminated(signum, frame):
    raise Terminated()


def stop_on_sigterm() -> None:
    """Make SIGTERM unwind the main process like SIGINT (call once, in the CLI's main thread)."""
    signal.signal(signal.SIGTERM, _raise_terminated)


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
    pool.shutdown(wait=False, cancel_futures=True)
    for p in procs:
        p.join(timeout=2.0)

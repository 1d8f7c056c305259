"""The one executor for every parallel stage: a local process pool, or a Dask cluster.

Every parallel job in govcheck (campaign runs, sweeps and yield runs, uncertainty bands,
diagnosis fits and benchmark cases, calibration searches, operating maps, report figures) is
``fn(context, item) -> result`` over a list of items, with one large read-only ``context``
that each worker receives once:

- ``local`` (default): a forked :func:`~compliance.processes.stopping.worker_pool` over the
  available cores. The context is set in module state before the fork, so nothing large is
  pickled; one worker (or no ``fork``) runs the items in this process.
- Dask (``--scheduler``, :mod:`compliance.processes.dask_cluster`): a ``distributed.Client`` on
  a scheduler address (``tcp://host:8786``) or on a ``LocalCluster`` started here
  (``local:N``). The context is scattered to every worker once (``broadcast``) and the items
  stream back as they finish.

A context that must be built in each worker (a fit context compiled from a plant file) is a
:class:`PerProcess`: sent as its recipe, built once per process on first use.

A finished task may add follow-up items (``follow``): they run on the same workers, before the items
not started yet or once every item has started (a stage whose last items leave a worker idle fills it
with work the next stage would otherwise run alone), each only while the caller still wants its result
(``wanted``); one no longer wanted is dropped, and if it is already running its worker is stopped with
the pool.

A task that raises (or whose worker dies: ``BrokenProcessPool``, Dask's ``KilledWorker``) is
submitted again, up to ``retries`` times; :class:`RunStats` counts done, failed and retried so
a run never drops an item silently. Progress: tqdm on a terminal, plain periodic lines
otherwise (CI logs).
"""

from __future__ import annotations

import math
import os
import sys
import time
from dataclasses import dataclass, field

from compliance.errors import GovcheckError
from compliance.processes.dask_cluster import dask_client, parse_scheduler
from compliance.processes.ledger import AFTER, AHEAD, Abandon, Ledger

__all__ = ["AFTER", "AHEAD", "PerProcess", "RunStats", "available_cores", "map_tasks"]

_CTX: dict = {}  # set before the pool forks: workers read the context without pickling it
_PLAIN_EVERY = 15.0  # seconds between plain progress lines when stderr is not a terminal


@dataclass
class RunStats:
    """What happened to the tasks of one :func:`map_tasks` call."""

    backend: str = "local"
    workers: int = 1
    done: int = 0
    failed: int = 0
    retried: int = 0
    errors: list = field(default_factory=list)  # (item index, last error text) of failed tasks
    wall: float = 0.0
    first_error: BaseException | None = field(default=None, repr=False, compare=False)

    def as_dict(self) -> dict:
        """Plain-JSON form."""
        return {"backend": self.backend, "workers": self.workers, "done": self.done, "failed": self.failed,
                "retried": self.retried, "errors": [list(e) for e in self.errors], "wall": self.wall}

    def raise_if_failed(self) -> None:
        """Raise the first failed task's own exception (for a stage that cannot do without any of its tasks)."""
        if self.failed:
            raise self.first_error


class PerProcess:
    """A worker context built once in each process that uses it, sent to workers as its recipe.

    ``PerProcess(build, *args).get()`` calls ``build(*args)`` on first use in a process and
    keeps the result; pickling (Dask) carries only ``build`` and ``args``. A forked worker
    inherits what the parent has already built.
    """

    def __init__(self, build, *args):
        self.build, self.args, self._value = build, args, None

    def get(self):
        """The built context of this process."""
        if self._value is None:
            self._value = self.build(*self.args)
        return self._value

    def __getstate__(self):
        return {"build": self.build, "args": self.args}

    def __setstate__(self, state):
        self.build, self.args, self._value = state["build"], state["args"], None


def available_cores() -> int:
    """Cores this process may run on (the one count: default of every ``--jobs``)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


class _Progress:
    """tqdm on a terminal; plain lines every ``_PLAIN_EVERY`` s otherwise; nothing when quiet."""

    def __init__(self, total: int, enabled: bool, label: str):
        self.total, self.done, self.label = total, 0, label
        self.enabled = enabled and total > 0
        self.bar = None
        self.t0 = self.last = time.perf_counter()
        if self.enabled and sys.stderr.isatty():
            from tqdm import tqdm

            self.bar = tqdm(total=total, desc=label, file=sys.stderr, leave=False, dynamic_ncols=True)

    def step(self, text: str = ""):
        self.done += 1
        if not self.enabled:
            return
        if self.bar is not None:
            self.bar.update(1)
            if text:
                self.bar.set_postfix_str(text[:40], refresh=False)
            return
        now = time.perf_counter()
        if now - self.last >= _PLAIN_EVERY or (self.done == self.total and self.last > self.t0):
            self.last = now
            print(f"{self.label}: {self.done}/{self.total} done, {now - self.t0:.0f} s", file=sys.stderr, flush=True)

    def close(self):
        if self.bar is not None:
            self.bar.close()


def _call(i: int):
    """Worker side of the local pool: the context was set before the fork."""
    return i, _CTX["fn"](_CTX["context"], _CTX["items"][i])


def _call_item(i: int, item):
    """Worker side of the local pool for a follow-up item (added after the fork: sent pickled)."""
    return i, _CTX["fn"](_CTX["context"], item)


def _run_serial(fn, context, items, sink: Ledger):
    while True:  # the follow-ups after every item given: each is asked whether it is wanted once all are known
        i = sink.todo.pop(0) if sink.todo else sink.next_task()
        if i is None:
            return
        while True:
            try:
                out = fn(context, sink.item(i))
            except GovcheckError:
                raise  # bad input is the user's to fix, not a lost task
            except Exception as exc:  # a failed task is retried, then counted
                if sink.failed(i, exc):
                    continue
            else:
                sink.done(i, out)
            break


def _run_pool(fn, context, items, sink: Ledger):
    from compliance.processes.stopping import worker_pool

    outer = dict(_CTX)  # a map_tasks inside a worker of another one: give the outer context back after
    _CTX.clear()
    _CTX.update(fn=fn, context=context, items=items)
    try:
        while sink.pending:  # a dead worker breaks the pool: start a new one for what is left
            sink.restart()
            try:
                with worker_pool(sink.stats.workers) as pool:
                    _drive_pool(pool, sink)
            except Abandon:
                pass
    finally:
        _CTX.clear()
        _CTX.update(outer)


def _in_flight(sink: Ledger) -> float:
    """Tasks a driver keeps submitted: all at once, or with follow-ups one per worker (the next one is chosen
    when a worker comes free)."""
    return sink.stats.workers if sink.follow is not None else math.inf


def _drive_pool(pool, sink: Ledger) -> None:
    """The tasks on ``pool``; returns when nothing wanted is left running (what failed and may run again is
    left pending for a new pool)."""
    from concurrent.futures import FIRST_COMPLETED, wait
    from concurrent.futures.process import BrokenProcessPool

    futures: dict = {}
    broken = False
    while True:
        while not broken and len(futures) < _in_flight(sink) and (i := sink.next_task()) is not None:
            fut = pool.submit(_call, i) if i < len(sink.items) else pool.submit(_call_item, i, sink.extra[i])
            futures[fut] = i
        if not sink.wanted_running(futures.values()):
            if futures:
                raise Abandon()  # stop their workers with the pool
            return
        finished, _ = wait(futures, return_when=FIRST_COMPLETED)
        for fut in sorted(finished, key=futures.get):
            i = futures.pop(fut)
            if i not in sink.pending:
                continue  # dropped while it ran
            try:
                _, out = fut.result()
            except GovcheckError:
                raise
            except (BrokenProcessPool, Exception) as exc:
                broken = broken or isinstance(exc, BrokenProcessPool)
                sink.failed(i, exc)
                continue
            sink.done(i, out)


def _run_dask(client, fn, context, items, sink: Ledger):
    from distributed import as_completed

    ctx = client.scatter(context, broadcast=True, hash=False)
    futures: dict = {}
    stream = as_completed()

    def submit(i: int):
        fut = client.submit(fn, ctx, sink.item(i), pure=False)
        futures[fut] = i
        stream.add(fut)

    while len(futures) < _in_flight(sink) and (i := sink.next_task()) is not None:
        submit(i)
    for fut in stream:
        i = futures.pop(fut)
        if i in sink.pending:  # else dropped while it ran
            try:
                out = fut.result()
            except GovcheckError:
                raise
            except Exception as exc:  # task error or KilledWorker: submit again, counted
                if sink.failed(i, exc):
                    if ctx.status != "finished":  # every worker holding the context died: send it again
                        ctx = client.scatter(context, broadcast=True, hash=False)
                    submit(i)
            else:
                sink.done(i, out)
        while len(futures) < _in_flight(sink) and (j := sink.next_task()) is not None:
            submit(j)
        if not sink.wanted_running(futures.values()):
            for f in futures:  # only follow-ups no longer wanted still run
                f.cancel()
            return


def _local_workers(workers: int | None, n: int) -> int:
    import multiprocessing as mp

    if "fork" not in mp.get_all_start_methods():
        return 1
    return max(1, min(workers or available_cores(), n)) if n else 1


def map_tasks(fn, context, items: list, *, scheduler: str | None = None, workers: int | None = None,
              progress: bool = True, label: str = "tasks", retries: int = 2, client=None, on_result=None,
              follow=None, wanted=None):
    """Run ``fn(context, item)`` for every item, locally or on Dask; results in item order.

    Parameters
    ----------
    fn : callable
        A module-level function (it is pickled by reference).
    context : object
        Read-only data every task needs, sent to each worker once.
    items : list
    scheduler : str, optional
        None / ``"local"``: the local process pool; ``"local:N"``: a Dask ``LocalCluster`` of N
        workers on the loopback interface; ``"tcp://host:port"``: an existing Dask scheduler.
    workers : int, optional
        Local pool size (default: available cores; 1 = in this process).
    progress : bool
        A progress bar (terminal) or plain lines (logs) named ``label``.
    retries : int
        Further attempts of a task that raised or lost its worker.
    client : distributed.Client, optional
        Use this client instead of connecting (a whole run's session, tests, benchmarks).
    on_result : callable, optional
        ``on_result(index, result)`` in this process as each task finishes (in finishing order).
    follow : callable, optional
        ``follow(index, result) -> items``, in this process as each task finishes (follow-ups' too): follow-up
        items, run on the same workers (``wanted``) in the order they were added; their results follow the
        items' in that order (index ``len(items)`` on). With follow-ups, a task is submitted when a worker comes
        free (without, all at once).
    wanted : callable, optional
        ``wanted(item) -> int`` of a follow-up, asked before it starts and as tasks finish: 0 (False; it must
        then stay 0) drops it, its result ``None``, its worker stopped if it runs (the local pool ends with it);
        ``AFTER`` (1, True) starts it once every item given has started; ``AHEAD`` (2) before the items given
        not started yet (in this process, ``workers=1``, every follow-up waits for every item given). Default:
        every follow-up ``AFTER``.

    Returns
    -------
    tuple
        (results, :class:`RunStats`); a task that failed every attempt, or a follow-up dropped, leaves ``None``.
    """
    t0 = time.perf_counter()
    n = len(items)
    kind, target = ("dask", None) if client is not None else parse_scheduler(scheduler)
    bar = _Progress(n, progress, label)
    try:
        if kind == "local":
            stats = RunStats("local", _local_workers(workers, n))
            sink = Ledger(items, bar, stats, retries, on_result, follow, wanted)
            (_run_serial if stats.workers == 1 else _run_pool)(fn, context, items, sink)
        else:
            own, cluster = (client, None) if client is not None else dask_client(kind, target)
            try:
                stats = RunStats("dask", len(own.scheduler_info().get("workers", {})) or 1)
                sink = Ledger(items, bar, stats, retries, on_result, follow, wanted)
                _run_dask(own, fn, context, items, sink)
            finally:
                if client is None:
                    own.close()
                    if cluster is not None:
                        cluster.close()
    finally:
        bar.close()
    stats.wall = time.perf_counter() - t0
    return sink.results, stats

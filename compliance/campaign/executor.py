"""One executor for campaigns, sweeps and yield runs: a local process pool, or a Dask cluster.

Every parallel job in govcheck is ``fn(context, item) -> result`` over a list of items, with
one large read-only ``context`` (the configuration, requirement set, planned runs) that each
worker receives once:

- ``local`` (default): a forked process pool over the available cores. The context is set in
  module state before the fork, so nothing large is pickled; one worker (or no ``fork``) runs
  the items in this process.
- ``dask``: a ``distributed.Client`` on a scheduler address (``tcp://host:8786``) or on a
  ``LocalCluster`` started here (``local:N``). The context is scattered to every worker once
  (``broadcast``) and the items stream back as they finish.

A task that raises (or whose worker dies: ``BrokenProcessPool``, Dask's ``KilledWorker``) is
submitted again, up to ``retries`` times; :class:`RunStats` counts done, failed and retried so
a run never drops an item silently. Progress: tqdm on a terminal, plain periodic lines
otherwise (CI logs).
"""

from __future__ import annotations

import copyreg
import os
from contextlib import contextmanager
import sys
import time
import types
from dataclasses import dataclass, field

from compliance.campaign.plan import Job
from compliance.errors import GovcheckError, InputError
from compliance.procedures.registry import run as run_procedure
from compliance.requirements.requirement_set import RequirementSet

__all__ = ["RunStats", "available_cores", "dask_session", "execute", "map_tasks", "parse_scheduler", "warm_up"]

_CTX: dict = {}  # set before the pool forks: workers read the context without pickling it
_PLAIN_EVERY = 15.0  # seconds between plain progress lines when stderr is not a terminal


def _mappingproxy(d):
    return types.MappingProxyType(d)


# Configurations are frozen with MappingProxyType, which pickle cannot carry; Dask pickles the
# context it scatters, so teach pickle to send the underlying dict and rebuild the proxy.
copyreg.pickle(types.MappingProxyType, lambda m: (_mappingproxy, (dict(m),)))


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

    def as_dict(self) -> dict:
        """Plain-JSON form."""
        return {"backend": self.backend, "workers": self.workers, "done": self.done, "failed": self.failed,
                "retried": self.retried, "errors": [list(e) for e in self.errors], "wall": self.wall}


def available_cores() -> int:
    """Cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


def parse_scheduler(text: str | None) -> tuple[str, object]:
    """``None`` -> ("local", None); ``"local:N"`` -> ("dask-local", N); ``"tcp://h:p"`` -> ("dask", address)."""
    if text is None or text == "local":
        return "local", None
    if text.startswith("local:"):
        try:
            n = int(text.split(":", 1)[1])
        except ValueError:
            n = 0
        if n < 1:
            raise InputError(f"--scheduler {text}: expected local:N with N >= 1 workers")
        return "dask-local", n
    if "://" in text:
        return "dask", text
    raise InputError(f"--scheduler {text}: expected a Dask scheduler address (tcp://host:8786) or local:N")


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


def _record_failure(i, exc, attempts, retries, stats, pending) -> bool:
    """Count a failed attempt; True when the item should run again."""
    attempts[i] = attempts.get(i, 0) + 1
    if attempts[i] <= retries:
        stats.retried += 1
        return True
    stats.failed += 1
    stats.errors.append((i, f"{type(exc).__name__}: {exc}"))
    pending.discard(i)
    return False


def _run_serial(fn, context, items, results, bar, stats, retries):
    attempts: dict = {}
    for i, item in enumerate(items):
        while True:
            try:
                results[i] = fn(context, item)
            except GovcheckError:
                raise  # bad input is the user's to fix, not a lost task
            except Exception as exc:  # a failed task is retried, then counted
                if _record_failure(i, exc, attempts, retries, stats, set()):
                    continue
            else:
                stats.done += 1
            bar.step()
            break


def _run_pool(fn, context, items, results, bar, stats, retries):
    from concurrent.futures import as_completed
    from concurrent.futures.process import BrokenProcessPool

    from compliance.processes import worker_pool

    pending, attempts = set(range(len(items))), {}
    _CTX.update(fn=fn, context=context, items=items)
    try:
        while pending:  # a dead worker breaks the pool: start a new one for what is left
            with worker_pool(stats.workers) as pool:
                futures = {pool.submit(_call, i): i for i in sorted(pending)}
                for fut in as_completed(futures):
                    i = futures[fut]
                    try:
                        _, out = fut.result()
                    except GovcheckError:
                        raise
                    except (BrokenProcessPool, Exception) as exc:
                        _record_failure(i, exc, attempts, retries, stats, pending)
                        continue
                    results[i] = out
                    pending.discard(i)
                    stats.done += 1
                    bar.step()
    finally:
        _CTX.clear()


def _dask_client(kind: str, target):
    from distributed import Client, LocalCluster

    if kind == "dask-local":
        import dask

        # a task whose worker dies comes straight back as KilledWorker, so that govcheck resubmits
        # it and counts the retry (the scheduler's own silent rescheduling would hide it)
        with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
            cluster = LocalCluster(n_workers=target, threads_per_worker=1, processes=True, host="127.0.0.1",
                                   dashboard_address="127.0.0.1:0")
        return Client(cluster), cluster
    _refuse_unreachable(target)
    try:
        return Client(target, timeout=30), None
    except OSError as exc:
        raise InputError(f"--scheduler {target}: cannot reach the Dask scheduler ({exc})") from None
    except Exception as exc:  # a service that is not Dask answers with bytes Dask's handshake cannot read
        raise InputError(f"--scheduler {target}: something answers there, but not as a Dask scheduler "
                         f"({exc.__class__.__name__}: {str(exc)[:120]})") from None


CONNECT_TIMEOUT = 5.0  # [s] a TCP connect to a live scheduler takes milliseconds; our choice of margin


def _refuse_unreachable(target: str) -> None:
    """Fail fast on a TCP scheduler address nothing listens on (Dask's Client retries for 30 s).

    One plain TCP connect, ``CONNECT_TIMEOUT`` at most: a refused connection (nothing on that
    port, loopback answers at once), an unknown host or a silent address is an
    :class:`InputError`. Other transports (``inproc``, ``ucx``, ...) are left to Dask.
    """
    import socket

    from distributed.comm.addressing import parse_address, parse_host_port

    scheme, location = parse_address(target)
    if scheme not in ("tcp", "tls"):
        return
    try:
        host, port = parse_host_port(location, default_port=8786)
    except ValueError as exc:
        raise InputError(f"--scheduler {target}: not a host:port address ({exc})") from None
    try:
        with socket.create_connection((host, port), timeout=CONNECT_TIMEOUT):
            return
    except socket.timeout:
        why = f"no answer within {CONNECT_TIMEOUT:g} s"
    except OSError as exc:
        why = exc.strerror or str(exc)
    raise InputError(
        f"--scheduler {target}: cannot reach the Dask scheduler at {host}:{port} ({why}); start one there "
        f"(dask scheduler --port {port}) or use --scheduler local:N"
    )


@contextmanager
def dask_session(scheduler: str | None, client=None):
    """One Dask client for a whole run of several ``map_tasks`` calls (a sweep and its remedies).

    Yields ``client`` when one is given, None for the local pool, else a client connected to
    ``scheduler`` (a ``LocalCluster`` started for ``local:N``), closed on exit.
    """
    kind, target = parse_scheduler(scheduler)
    if client is not None or kind == "local":
        yield client
        return
    own, cluster = _dask_client(kind, target)
    try:
        yield own
    finally:
        own.close()
        if cluster is not None:
            cluster.close()


def _run_dask(client, fn, context, items, results, bar, stats, retries):
    from distributed import as_completed

    ctx = client.scatter(context, broadcast=True, hash=False)
    attempts: dict = {}
    pending = set(range(len(items)))
    futures = {client.submit(fn, ctx, items[i], pure=False): i for i in range(len(items))}
    stream = as_completed(list(futures))
    for fut in stream:
        i = futures.pop(fut)
        try:
            out = fut.result()
        except GovcheckError:
            raise
        except Exception as exc:  # task error or KilledWorker: submit again, counted
            if _record_failure(i, exc, attempts, retries, stats, pending):
                again = client.submit(fn, ctx, items[i], pure=False)
                futures[again] = i
                stream.add(again)
            continue
        results[i] = out
        pending.discard(i)
        stats.done += 1
        bar.step()


def map_tasks(fn, context, items: list, *, scheduler: str | None = None, workers: int | None = None,
              progress: bool = True, label: str = "tasks", retries: int = 2, client=None):
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
    retries : int
        Further attempts of a task that raised or lost its worker.
    client : distributed.Client, optional
        Use this client instead of connecting (tests, benchmarks).

    Returns
    -------
    tuple
        (results, :class:`RunStats`); a task that failed every attempt leaves ``None``.
    """
    t0 = time.perf_counter()
    n = len(items)
    kind, target = ("dask", None) if client is not None else parse_scheduler(scheduler)
    results: list = [None] * n
    bar = _Progress(n, progress, label)
    try:
        if kind == "local":
            import multiprocessing as mp

            w = max(1, min(workers or available_cores(), n)) if n else 1
            if "fork" not in mp.get_all_start_methods():
                w = 1
            stats = RunStats("local", w)
            runner = _run_serial if w == 1 else _run_pool
            runner(fn, context, items, results, bar, stats, retries)
        else:
            own, cluster = (client, None) if client is not None else _dask_client(kind, target)
            try:
                stats = RunStats("dask", len(own.scheduler_info().get("workers", {})) or 1)
                _run_dask(own, fn, context, items, results, bar, stats, retries)
            finally:
                if client is None:
                    own.close()
                    if cluster is not None:
                        cluster.close()
    finally:
        bar.close()
    stats.wall = time.perf_counter() - t0
    return results, stats


# --------------------------------------------------------------------------- campaigns
def warm_up(cfg):
    """Compile (or load from the numba cache) the simulator core once, before workers fork."""
    from compliance.simulation import Scenario, simulate

    simulate(cfg, Scenario(0.01, 0.5 * cfg.p("cylinder.stroke")))
    if cfg.options["controller.type"] != "pid":
        from compliance.simulation.state_feedback_loop import warm_up as warm_up_state_feedback

        warm_up_state_feedback(cfg)


def _campaign_run(context, job: Job):
    cfg, reqset = context
    return run_procedure(cfg, reqset.procedures[job.procedure], reqset.operating_points[job.operating_point], job.requests)


def execute(cfg, reqset: RequirementSet, jobs: list[Job], *, workers: int | None = None, progress: bool = True,
            scheduler: str | None = None):
    """Run a campaign's jobs, in parallel when there are several cores and several jobs.

    Returns
    -------
    tuple
        (outcomes in job order, number of workers used)
    """
    if jobs:
        warm_up(cfg)
    outcomes, stats = map_tasks(_campaign_run, (cfg, reqset), list(jobs), scheduler=scheduler, workers=workers,
                                progress=progress, label="runs", retries=1)
    if stats.failed:  # a run that crashed twice (not a simulation error: those are recorded) is a bug
        i, why = stats.errors[0]
        raise RuntimeError(f"run {jobs[i].key} failed: {why}")
    return outcomes, stats.workers

"""Parallel work: the one executor (:func:`map_tasks`, local pool or Dask) and the process pool that stops with the run.

- :mod:`~compliance.processes.stopping`: :func:`worker_pool` (the one process pool) and the
  signal handling that kills its workers when the run is interrupted;
- :mod:`~compliance.processes.executor`: :func:`map_tasks`, the one way every stage runs
  ``fn(context, item)`` over items, counting cores one way (:func:`available_cores`);
- :mod:`~compliance.processes.dask_cluster`: the ``--scheduler`` option (``local:N`` or a Dask
  scheduler address) and one Dask session per run.
"""

from compliance.processes.dask_cluster import dask_session, parse_scheduler
from compliance.processes.executor import AFTER, AHEAD, PerProcess, RunStats, available_cores, map_tasks
from compliance.processes.stopping import (GRACE, Terminated, raise_if_stopping, stop_on_signals, stop_signal,
                                           worker_pool)

__all__ = ["AFTER", "AHEAD", "GRACE", "PerProcess", "RunStats", "Terminated", "available_cores", "dask_session", "map_tasks",
           "parse_scheduler", "raise_if_stopping", "stop_on_signals", "stop_signal", "worker_pool"]

"""What one :func:`~compliance.processes.executor.map_tasks` call has left to start and where its results go.

A :class:`Ledger` holds the items given, the results in item order, the counts (``RunStats``), and the
follow-up items finished tasks add (``map_tasks``' ``follow``): each with an urgency the caller's
``wanted`` gives (``AFTER`` the items given, ``AHEAD`` of those not started, 0: dropped). The drivers
of the executor (in this process, the local pool, Dask) ask it what starts next.
"""

from __future__ import annotations

__all__ = ["AFTER", "AHEAD", "Abandon", "Ledger"]

AFTER, AHEAD = 1, 2  # a follow-up's urgency (``map_tasks``' ``wanted``): once the items given have started, or before


class Abandon(Exception):
    """Only follow-ups no longer wanted are running: the pool stops with them."""


class Ledger:
    """Where finished tasks go: the results list, the counts, the progress bar and the caller's callbacks;
    what is left to start (``map_tasks``' items, and the follow-ups finished tasks added)."""

    def __init__(self, items: list, bar, stats, retries: int, on_result, follow=None, wanted=None):
        self.items = items
        self.results: list = [None] * len(items)
        self.bar, self.stats, self.retries, self.on_result = bar, stats, retries, on_result
        self.follow, self.wanted = follow, wanted
        self.attempts: dict = {}
        self.pending = set(range(len(items)))
        self.extra: dict = {}  # index -> follow-up item (indices after the items given)
        self.todo: list = list(range(len(items)))  # items given not started yet
        self.queue: list = []  # follow-ups not started yet, in the order they were added

    def item(self, i: int):
        return self.items[i] if i < len(self.items) else self.extra[i]

    def restart(self) -> None:
        """A new pool: everything pending starts again (an item that failed, a follow-up lost with its worker)."""
        self.todo = sorted(i for i in self.pending if i < len(self.items))
        self.queue = sorted(j for j in self.pending if j in self.extra)

    def urgency(self, j: int) -> int:
        return int(self.wanted(self.extra[j])) if self.wanted is not None else AFTER

    def next_task(self) -> int | None:
        """What starts next: a follow-up wanted ``AHEAD``, else the next item given, else a follow-up still wanted."""
        self.drop_unwanted()
        ahead = next((j for j in self.queue if self.urgency(j) >= AHEAD), None)
        i = ahead if ahead is not None else self.todo.pop(0) if self.todo else self.queue[0] if self.queue else None
        if i in self.queue:
            self.queue.remove(i)
        return i

    def done(self, i: int, out) -> None:
        self.results[i] = out
        self.pending.discard(i)
        self.stats.done += 1
        if i < len(self.items):
            self.bar.step()
        if self.on_result is not None:
            self.on_result(i, out)
        for item in (self.follow(i, out) if self.follow is not None else ()):
            j = len(self.results)
            self.results.append(None)
            self.extra[j] = item
            self.pending.add(j)
            self.queue.append(j)

    def drop_unwanted(self) -> None:
        """Follow-ups whose results the caller no longer wants leave the run (their results stay None)."""
        for j in sorted(j for j in self.pending if j in self.extra and not self.urgency(j)):
            self.pending.discard(j)
        self.queue = [j for j in self.queue if j in self.pending]

    def failed(self, i: int, exc: BaseException) -> bool:
        """Count a failed attempt; True when the item should run again."""
        self.attempts[i] = self.attempts.get(i, 0) + 1
        if self.attempts[i] <= self.retries:
            self.stats.retried += 1
            return True
        self.stats.failed += 1
        self.stats.errors.append((i, f"{type(exc).__name__}: {exc}"))
        if self.stats.first_error is None:
            self.stats.first_error = exc
        self.pending.discard(i)
        if i < len(self.items):
            self.bar.step()
        return False

    def wanted_running(self, running) -> bool:
        """Whether any of the ``running`` indices is still wanted (False: stop what runs)."""
        self.drop_unwanted()
        return any(i in self.pending for i in running)

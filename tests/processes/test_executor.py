"""The one executor: local pool and a real Dask LocalCluster give identical sweeps; lost tasks are retried and counted."""

import os

import pandas as pd
import pytest

from compliance.processes import map_tasks, parse_scheduler
from compliance.sweep.run import load_inputs
from compliance.sweep.candidates.evaluate import make_context
from compliance.sweep.candidates.results import table
from compliance.sweep.candidates.runner import run_candidates
from compliance.sweep.candidates.sampling import grid
from compliance.sweep.candidates.spec import load_sweep

from tests.sweep.conftest import sweep_text, write_sweep  # noqa: F401 - the sweep file fixture


def _fail_first(marker_dir, item):
    """Raises on the first attempt of item 3 (a marker file remembers across processes)."""
    marker = os.path.join(marker_dir, f"seen-{item}")
    if item == 3 and not os.path.exists(marker):
        open(marker, "w").close()
        raise RuntimeError("simulated lost task")
    return item * item


def _die_first(marker_dir, item):
    """Kills its worker process on the first attempt of item 2 (BrokenProcessPool in the parent)."""
    marker = os.path.join(marker_dir, f"died-{item}")
    if item == 2 and not os.path.exists(marker):
        open(marker, "w").close()
        os._exit(1)
    return item + 100


def test_scheduler_addresses():
    assert parse_scheduler(None) == ("local", None)
    assert parse_scheduler("local:3") == ("dask-local", 3)
    assert parse_scheduler("tcp://10.0.0.5:8786") == ("dask", "tcp://10.0.0.5:8786")


def test_unreachable_scheduler_is_refused_at_once():
    import socket
    import time

    from compliance.processes.dask_cluster import CONNECT_TIMEOUT
    from compliance.errors import InputError

    with socket.socket() as s:  # a loopback port that was free a moment ago: nothing listens there
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    t0 = time.perf_counter()
    with pytest.raises(InputError, match=f"cannot reach the Dask scheduler at 127.0.0.1:{port} \\(Connection refused\\)"):
        map_tasks(abs, None, [1, 2], scheduler=f"tcp://127.0.0.1:{port}", progress=False)
    # loopback refuses within milliseconds; Dask's own client would retry for its 30 s timeout
    assert time.perf_counter() - t0 < CONNECT_TIMEOUT


@pytest.mark.parametrize("workers", [1, 2])
def test_failed_task_is_retried_and_counted_locally(tmp_path, workers):
    out, stats = map_tasks(_fail_first, str(tmp_path), list(range(6)), workers=workers, progress=False)
    assert out == [i * i for i in range(6)]
    assert (stats.done, stats.failed, stats.retried) == (6, 0, 1)


def test_killed_worker_is_retried_and_counted(tmp_path):
    out, stats = map_tasks(_die_first, str(tmp_path), list(range(5)), workers=2, progress=False)
    assert out == [i + 100 for i in range(5)]
    assert stats.failed == 0 and stats.retried >= 1  # the dead worker's task, and any sharing its pool


def test_task_failing_every_attempt_is_counted_not_dropped(tmp_path):
    def always(ctx, item):
        raise ValueError("broken")
    out, stats = map_tasks(always, None, [1, 2], workers=1, progress=False, retries=1)
    assert out == [None, None] and (stats.done, stats.failed, stats.retried) == (0, 2, 2)


def test_failed_task_is_retried_on_dask(tmp_path, dask_client):
    out, stats = map_tasks(_fail_first, str(tmp_path), list(range(6)), client=dask_client, progress=False)
    assert out == [i * i for i in range(6)]
    assert (stats.backend, stats.done, stats.retried) == ("dask", 6, 1)


def test_small_sweep_local_equals_dask(write_sweep, dask_client):
    spec = load_sweep(write_sweep(sweep_text()))
    cfg, reqset = load_inputs(spec)
    ctx = make_context(cfg, reqset, spec.paths)
    cands = grid(spec.adjust)
    assert len(cands) == 8
    local, st_l = run_candidates(ctx, cands, workers=2, progress=False)
    remote, st_d = run_candidates(ctx, cands, client=dask_client, progress=False)
    ids = [r.id for r in ctx.reqset.requirements]
    a, b = table(cands, local, ids), table(cands, remote, ids)
    pd.testing.assert_frame_equal(a, b)
    assert st_l.failed == st_d.failed == 0 and st_l.done == st_d.done >= 2  # every batch done, none lost
    # physics, not plumbing: a stiffer proportional gain shortens the time constant (static friction
    # is overcome sooner), so along kp at kd = 10 V*s/m the time constant falls
    tc = a[a["controller.kd"] == 10.0].sort_values("controller.kp")["TC.value"].dropna().to_numpy()
    assert len(tc) >= 2 and all(tc[1:] < tc[:-1])


@pytest.mark.slow
def test_killed_dask_worker_process_is_retried_and_counted(tmp_path):
    # a real LocalCluster of 2 worker processes on 127.0.0.1, started and stopped here (local:2). The death
    # of one worker fails every task it held (allowed-failures = 0); on a loaded machine a missed heartbeat can
    # also fail a task of a live worker once, so more attempts than the default keep the count honest, not flaky
    out, stats = map_tasks(_die_first, str(tmp_path), list(range(5)), scheduler="local:2", progress=False, retries=5)
    assert out == [i + 100 for i in range(5)]
    assert stats.backend == "dask" and stats.failed == 0 and stats.retried >= 1


def _square(ctx, item):
    return item * item


def test_progress_is_plain_lines_when_not_a_terminal(monkeypatch, capsys):
    import compliance.processes.executor as ex

    monkeypatch.setattr(ex, "_PLAIN_EVERY", 0.0)  # every completion prints (CI logs get one per interval)
    out, _ = map_tasks(_square, None, [1, 2, 3], workers=1, progress=True, label="candidates")
    err = capsys.readouterr().err
    assert out == [1, 4, 9]
    assert "candidates: 3/3 done" in err and "\r" not in err
    map_tasks(_square, None, [1, 2, 3], workers=1, progress=False)
    assert capsys.readouterr().err == ""


def _square_or_follow(ctx, item):
    """A number: its square; a follow-up (value, seconds): sleeps, then ("followed", value)."""
    import time

    if isinstance(item, tuple):
        time.sleep(item[1])
        return ("followed", item[0])
    return item * item


@pytest.mark.parametrize("backend", ["serial", "pool", "dask"])
def test_follow_ups_run_while_wanted_and_come_after_the_items_in_the_order_added(backend, request):
    from compliance.processes import AFTER

    added = []

    def follow(i, out):
        if i >= 4:
            return []
        added.append((out, 0.0))
        return [added[-1]]

    def wanted(item):  # the follow-ups of odd squares are not wanted
        return 0 if item[0] % 2 else AFTER

    where = {"serial": {"workers": 1}, "pool": {"workers": 2}, "dask": {"client": None}}[backend]
    if backend == "dask":
        where = {"client": request.getfixturevalue("dask_client")}
    out, stats = map_tasks(_square_or_follow, None, [1, 2, 3, 4], progress=False, follow=follow, wanted=wanted, **where)
    assert out[:4] == [1, 4, 9, 16] and len(out) == 8 and sorted(a[0] for a in added) == [1, 4, 9, 16]
    assert out[4:] == [None if v % 2 else ("followed", v) for v, _ in added]
    assert stats.done == 6 and stats.failed == 0


def test_a_running_follow_up_no_longer_wanted_is_stopped_with_the_pool():
    import time

    from compliance.processes import AFTER

    known = set()

    def follow(i, out):
        known.add(i)
        return [(-1, 60.0)] if i == 0 else []  # a minute's follow-up, wanted until item 1 is known

    t0 = time.perf_counter()
    out, stats = map_tasks(_square_or_follow, None, [0, (1, 1.0)], workers=2, progress=False, follow=follow,
                           wanted=lambda item: 0 if 1 in known else AFTER)
    assert out == [0, ("followed", 1), None] and stats.failed == 0
    assert time.perf_counter() - t0 < 20.0  # not the follow-up's minute


def _started(ctx, item):
    import time

    t = time.time()
    time.sleep(item[1])
    return item[0], t


def test_a_follow_up_wanted_ahead_starts_before_the_items_not_started_yet():
    from compliance.processes import AHEAD

    items = [("quick", 0.0)] + [(f"item{k}", 0.4) for k in range(4)]
    out, _ = map_tasks(_started, None, items, workers=2, progress=False,
                       follow=lambda i, out: [("ahead", 0.0)] if i == 0 else [], wanted=lambda item: AHEAD)
    start = dict(out)
    # two workers: "quick" and item0 start first; the follow-up of "quick" then comes before items 1 to 3
    assert start["ahead"] < min(start["item1"], start["item2"], start["item3"])

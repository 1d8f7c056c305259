"""SIGINT and SIGTERM stop every long command within 5 s, workers included, and nothing is left written.

Each command runs as a real process in its own session (so every process it starts can be
found afterwards: same session id). The test decides both things a machine would otherwise
decide: how many workers (``-j 2`` on every command) and when the signal arrives:

- ``workers``: once the command's own worker processes run - children forked from it, so their
  command line is the command's own (a helper program such as ``ldconfig``, which a library may
  run while being imported, is not a worker);
- ``starting``: while the command is still importing its modules (numpy is being loaded: no
  command is importable without it, and govcheck's own start-up code has run by then).

The compiled core is loaded into numba's cache before any command is timed (a first compilation holds
the interpreter for seconds at a time and is a one-off of a fresh checkout, not a moment a user
stops a run in). The whole session must be gone 5 s after the signal, the exit code must be 130 (SIGINT) or 143
(SIGTERM), stderr must hold one line and no traceback, and the workspace must hold no new file
or folder and no temporary file.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.bad_inputs import workspace as W
from tests.bad_inputs.cases import SWEEP

REPO = Path(__file__).resolve().parents[2]
STOP_WITHIN = 5.0  # [s] the bound
READY_WITHIN = 300.0  # [s] for the moment to come on a loaded machine (imports and numba's cache load take seconds)
JOBS = "2"  # worker processes of every command: the test's choice, not the machine's core count


@pytest.fixture(scope="module", autouse=True)
def compiled_core(tmp_path_factory):
    """Compile (or load) the simulator's core and the replay once, so the commands under test find them in numba's
    cache (a replay of the workspace's 0.2 s recording compiles what the diagnosis runs before its workers start)."""
    from compliance.cli import main

    ws = tmp_path_factory.mktemp("warm")
    W.build(ws)
    assert main(["validate", str(ws / "plant.toml"), str(ws / "rec.csv"), "-q"]) in (0, 1)


def _stat(pid: int) -> list[str] | None:
    try:
        return (Path("/proc") / str(pid) / "stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return None


def _session(sid: int) -> list[int]:
    """Live processes (not zombies) whose session id is ``sid``."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            fields = _stat(int(entry.name))  # fields: state ppid pgrp session ...
            if fields and int(fields[3]) == sid and fields[0] != "Z":
                found.append(int(entry.name))
    return found


def _cmdline(pid: int) -> bytes:
    try:
        return (Path("/proc") / str(pid) / "cmdline").read_bytes()
    except OSError:
        return b""


def _workers(pid: int) -> list[int]:
    """Children of ``pid`` forked from it (same command line): its worker processes."""
    own = _cmdline(pid)
    return [p for p in _session(pid) if p != pid and (_stat(p) or ["", "0"])[1] == str(pid) and _cmdline(p) == own]


def _importing_numpy(pid: int) -> bool:
    try:
        maps = (Path("/proc") / str(pid) / "maps").read_text()
    except OSError:
        return False
    return "numpy" in maps


def _as_from_a_terminal():
    """SIGINT as a foreground command on a terminal has it (a background job of a script inherits it ignored)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


# 400 candidates (20 x 20 grid): the size the issue found deaf to SIGINT for over 120 s
SWEEP_400 = SWEEP.replace('values = ["280 V/m", "300 V/m"]', 'range = ["200 V/m", "400 V/m"]\nsteps = 20') + \
    '\n[adjust."controller.kd"]\nrange = ["10 V*s/m", "30 V*s/m"]\nsteps = 20\n'
DUTY = (REPO / "models" / "duties" / "plant-a.toml").read_text(encoding="utf-8")

COMMANDS = {
    "check": ["check", "plant-a", "-r", "shpp-400kw", "-j", JOBS, "--json", "r.json", "-q"],
    "sweep": ["sweep", "s.toml", "--out", "sweep-out", "-j", JOBS, "-q"],
    "diagnose": ["diagnose", "plant.toml", "rec.csv", "-j", JOBS, "--json", "d.json", "-q"],
    "calibrate": ["reproduce", "plant.toml", "--calibrate", "cal.toml", "-j", JOBS],
    "size": ["size", "shpp-400kw", "--duty", "duty.toml", "--out", "sized.toml", "-j", JOBS, "--json", "s.json", "-q"],
}
MOMENTS = {"workers": _workers, "starting": _importing_numpy}


def _run_and_signal(tmp_path, argv, sig, ready) -> tuple[int, str, list, float]:
    """Start ``govcheck argv`` in ``tmp_path``, send ``sig`` once ``ready(pid)`` holds; (exit code, stderr, leftovers, stop time)."""
    env = dict(os.environ, PYTHONPATH=str(REPO), PYTHONFAULTHANDLER="1")  # SIGABRT on a hang dumps every thread
    env.pop("SOURCE_DATE_EPOCH", None)
    log = tmp_path.parent / f"{tmp_path.name}.stderr"  # a file, not a pipe: a full pipe would stall the command
    proc = subprocess.Popen([sys.executable, "-m", "compliance", *argv], cwd=tmp_path, env=env,
                            stdout=subprocess.DEVNULL, stderr=log.open("wb"), start_new_session=True,
                            preexec_fn=_as_from_a_terminal)
    try:
        t0 = time.monotonic()
        while not ready(proc.pid) and time.monotonic() - t0 < READY_WITHIN and proc.poll() is None:
            time.sleep(0.02)
        assert proc.poll() is None, f"{argv[0]} ended before the signal: {log.read_text()[-400:]}"
        assert ready(proc.pid), f"{argv[0]}: the moment to signal did not come within {READY_WITHIN:g} s"
        proc.send_signal(sig)
        sent = time.monotonic()
        try:
            code = proc.wait(timeout=STOP_WITHIN + 5)
        except subprocess.TimeoutExpired:
            proc.send_signal(signal.SIGABRT)
            proc.wait(timeout=10)
            pytest.fail(f"{argv[0]} still running {STOP_WITHIN + 5:g} s after the signal; its threads:\n{log.read_text()[-6000:]}")
        stopped = time.monotonic() - sent
        while _session(proc.pid) and time.monotonic() < sent + STOP_WITHIN:
            time.sleep(0.05)
        left = _session(proc.pid)
    finally:
        for p in _session(proc.pid):
            os.kill(p, signal.SIGKILL)
        if proc.poll() is None:
            proc.kill()
    return code, log.read_text(), left, stopped


def _workspace(tmp_path):
    W.build(tmp_path)
    (tmp_path / "s.toml").write_text(SWEEP_400, encoding="utf-8")
    (tmp_path / "duty.toml").write_text(DUTY, encoding="utf-8")
    return {p.relative_to(tmp_path) for p in tmp_path.rglob("*")}


def _check_stopped(tmp_path, before, command, sig, code, err, left, stopped):
    assert stopped < STOP_WITHIN, f"{command} took {stopped:.1f} s to stop"
    assert not left, f"processes left behind after {command}: {left}"
    assert code == (130 if sig == signal.SIGINT else 143), f"exit {code}: {err[-400:]}"
    assert "Traceback" not in err, err[-800:]
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1 and ("interrupted" in lines[0] or "terminated" in lines[0] or "stopped" in lines[0]), err[-800:]
    after = {p.relative_to(tmp_path) for p in tmp_path.rglob("*")}
    new = {p for p in after - before if "__pycache__" not in p.parts}
    assert not new, f"{command} left {sorted(map(str, new))}"


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_signal_stops_command_and_workers(tmp_path, command, sig):
    before = _workspace(tmp_path)
    code, err, left, stopped = _run_and_signal(tmp_path, COMMANDS[command], sig, MOMENTS["workers"])
    _check_stopped(tmp_path, before, command, sig, code, err, left, stopped)


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_signal_while_starting_is_one_line_and_exit_code(tmp_path, sig):
    """A Ctrl-C while the command's modules are still being imported: no KeyboardInterrupt traceback."""
    before = _workspace(tmp_path)
    code, err, left, stopped = _run_and_signal(tmp_path, COMMANDS["check"], sig, MOMENTS["starting"])
    _check_stopped(tmp_path, before, "check (starting)", sig, code, err, left, stopped)

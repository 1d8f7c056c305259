"""Progress when stderr is not a terminal: whole lines (tqdm), none when quiet."""

from __future__ import annotations

import io
import sys

from compliance.cli import progress as P


def test_progress_lines_in_a_log(monkeypatch):
    buf = io.StringIO()
    monkeypatch.setattr(sys, "stderr", buf)
    monkeypatch.setattr(P, "LOG_INTERVAL", 0.0)  # no heartbeat thread; every update a line
    with P.progress(3, "check", unit="stage") as bar:
        for _ in range(3):
            bar.update(1)
    lines = buf.getvalue().splitlines()
    assert "\r" not in buf.getvalue()
    assert lines and lines[-1].startswith("check: 100%") and "3/3" in lines[-1]


def test_quiet_prints_nothing(monkeypatch):
    buf = io.StringIO()
    monkeypatch.setattr(sys, "stderr", buf)
    with P.progress(2, "x", quiet=True) as bar:
        bar.update(2)
    assert buf.getvalue() == ""


def test_heartbeat_line_during_a_long_stage(monkeypatch):
    import time

    buf = io.StringIO()
    monkeypatch.setattr(sys, "stderr", buf)
    monkeypatch.setattr(P, "LOG_INTERVAL", 0.05)
    with P.progress(1, "diagnose", unit="stage") as bar:
        time.sleep(0.3)  # one long stage, no update
        bar.update(1)
    lines = [ln for ln in buf.getvalue().splitlines() if ln.startswith("diagnose:")]
    assert len(lines) >= 3  # the start, at least one heartbeat, the end

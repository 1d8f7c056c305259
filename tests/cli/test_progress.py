"""Progress when stderr is not a terminal: whole lines (tqdm), none when quiet."""

from __future__ import annotations

import io
import sys

from compliance.cli import progress as P


def test_progress_lines_in_a_log(monkeypatch):
    buf = io.StringIO()
    monkeypatch.setattr(sys, "stderr", buf)
    monkeypatch.setattr(P, "LOG_INTERVAL", 0.0)
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

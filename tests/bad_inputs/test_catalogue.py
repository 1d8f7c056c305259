"""Run the bad-input catalogue: exit code, one clear message, no traceback, nothing written or changed."""

from __future__ import annotations


import pytest

from compliance.cli import main
from tests.bad_inputs import workspace as W
from tests.bad_inputs import new_user
from tests.bad_inputs.cases import CASES as OLDER

CASES = OLDER + new_user.CASES


def _materialise(ws, files):
    for name, content in files.items():
        if callable(content):
            content(ws)
        elif isinstance(content, bytes):
            (ws / name).write_bytes(content)
        else:
            (ws / name).write_text(content, encoding="utf-8")


def test_catalogue_size_and_ids():
    ids = [c.id for c in CASES]
    assert len(ids) == len(set(ids)), "duplicate case ids"
    assert len(CASES) >= 120
    kinds = {i.split("-")[0] for i in ids}
    assert {"config", "req", "csv", "mat", "parquet", "comtrade", "sim", "out"} <= kinds


def test_new_user_catalogue_covers_the_newer_features():
    """At least 40 new-user cases over the newer features, every class of them present."""
    ids = [c.id for c in new_user.CASES]
    newer = [i for i in ids if not i.startswith("older-")]
    assert len(newer) >= 40, len(newer)
    assert {i.split("-")[0] for i in newer} == set(new_user.CLASSES)


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_bad_input(case, tmp_path, monkeypatch, capsys):
    ws = tmp_path / "ws"
    ws.mkdir()
    W.build(ws)
    _materialise(ws, case.files)
    monkeypatch.chdir(ws)
    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    for k, v in case.env.items():
        monkeypatch.setenv(k, v)
    before = W.tree_digest(ws)
    code = main(list(case.argv))
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    assert code == case.code, f"exit {code}, expected {case.code}; stderr: {err.strip()[-400:]}"
    assert case.fragment in err, f"message lacks {case.fragment!r}: {err.strip()[-400:]}"
    assert sum(line.startswith("govcheck") for line in err.splitlines()) == 1, f"expected one message: {err}"
    assert W.tree_digest(ws) == before, "the failed run wrote or changed files"
    assert not any(p.name.endswith(".tmp") or ".tmp." in p.name for p in ws.rglob("*")), "temporary file left behind"

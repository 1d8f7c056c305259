"""compliance.files: the one JSON cleaner, the atomic writer's permissions, output checks, reproducibility."""

from __future__ import annotations

import json
import os
import stat

import numpy as np
import pytest

from compliance.errors import InputError
from compliance.files.atomic import write_bytes_atomic, write_json_atomic, write_text_atomic
from compliance.files.jsonable import json_text, jsonable
from compliance.files.outputs import check_output, check_outputs
from compliance.files.reproducible import fixed_created, is_reproducible, make_reproducible


def test_jsonable_numpy_nan_and_keys():
    data = {1: np.float32(0.5), "a": np.array([1.0, np.nan, np.inf]), "b": (np.int64(3), np.bool_(True)), "c": float("-inf")}
    assert jsonable(data) == {"1": 0.5, "a": [1.0, None, None], "b": [3, True], "c": None}
    text = json_text({"x": np.nan}, compact=True)
    assert text == '{"x":null}\n'
    assert json.loads(json_text({"y": np.arange(3)})) == {"y": [0, 1, 2]}


def test_one_json_cleaner_in_the_package():
    """Every JSON cleaner of the CLI and the result writers is compliance.files.jsonable."""
    from compliance.campaign import results_files
    from compliance.cli import characterise, diagnose_benchmark
    from compliance.linear import analysis

    assert analysis.jsonable is jsonable
    for mod in (results_files, characterise, diagnose_benchmark):
        assert not hasattr(mod, "_clean") and not hasattr(mod, "_plain") and not hasattr(mod, "_finite")


def test_same_permissions_for_every_writer(tmp_path):
    umask = os.umask(0o022)
    try:
        write_text_atomic(tmp_path / "a.md", "x")
        write_bytes_atomic(tmp_path / "b.csv", b"time\n0\n")
        write_json_atomic(tmp_path / "c.json", {"a": 1})
    finally:
        os.umask(umask)
    modes = {stat.S_IMODE((tmp_path / n).stat().st_mode) for n in ("a.md", "b.csv", "c.json")}
    assert modes == {0o644}
    assert not list(tmp_path.glob(".*tmp*"))


def test_read_only_target_is_not_replaced(tmp_path):
    target = tmp_path / "r.json"
    target.write_text("{}\n")
    target.chmod(0o444)
    with pytest.raises(InputError, match="read-only"):
        write_json_atomic(target, {"a": 1})
    assert target.read_text() == "{}\n"


def test_check_outputs_messages(tmp_path):
    (tmp_path / "dir.json").mkdir()
    with pytest.raises(InputError, match="is a folder"):
        check_output(tmp_path / "dir.json", "--json", (".json",))
    with pytest.raises(InputError, match="does not exist"):
        check_output(tmp_path / "no" / "x.json", "--json")
    with pytest.raises(InputError, match=r"ending in \.png"):
        check_output(tmp_path / "p.jpg", "--plot", (".png", ".svg", ".pdf"))
    with pytest.raises(InputError, match="the same file as --json"):
        check_outputs((tmp_path / "x.json", "--json"), (tmp_path / "x.json", "--markdown"))
    check_outputs((None, "--pdf"), (tmp_path / "ok.json", "--json", (".json",)))


def test_reproducible_fixed_created_and_no_timings(monkeypatch):
    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    assert not is_reproducible(False) and is_reproducible(True)
    assert fixed_created() == "1970-01-01T00:00:00+00:00"
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    assert is_reproducible(False)
    assert fixed_created() == "2023-11-14T22:13:20+00:00"
    res = {"schema": "s", "created": "now", "command_line": "govcheck check p --json /tmp/x.json",
           "timing": {"wall": 3.0}, "runs": [{"id": "a", "wall_time": 1.2}]}
    out = make_reproducible(res, "govcheck check p")
    assert out == {"schema": "s", "created": "2023-11-14T22:13:20+00:00", "command_line": "govcheck check p",
                   "runs": [{"id": "a"}], "reproducible": True}
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "soon")
    with pytest.raises(InputError, match="SOURCE_DATE_EPOCH"):
        fixed_created()

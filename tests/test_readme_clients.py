"""The README's python-control and ANDES examples run as written and reproduce govcheck's own figures.

Each example is the ```python block after its ``<!-- readme-example: NAME -->`` marker; it is run
as it stands, its printed lines must be those the README shows (``# ->``), and its results are
compared with what govcheck computes itself: the closed-loop poles and continuous margins of
``govcheck linear`` at the same point, and the closing move time of the governor export.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from compliance.cli import main

README = Path(__file__).resolve().parents[1] / "README.md"


def _example(name: str) -> str:
    found = dict(re.findall(r"<!-- readme-example: ([\w-]+) -->\n```python\n(.*?)```", README.read_text(encoding="utf-8"),
                            flags=re.S))
    assert name in found, f"README has no example '{name}'"
    return found[name]


def _run(name: str, capsys) -> tuple[dict, str]:
    code = _example(name)
    ns: dict = {}
    exec(compile(code, f"README.md ({name})", "exec"), ns)
    out = capsys.readouterr().out
    for line in re.findall(r"^# -> (.+)$", code, flags=re.M):
        assert line in out, f"README prints {line!r}; the example printed:\n{out}"
    return ns, out


def test_python_control_example_gives_govcheck_linear_poles_and_margins(tmp_path, capsys):
    import control

    ns, _ = _run("python-control", capsys)
    m = ns["m"]
    out = tmp_path / "lin.json"
    assert main(["linear", "plant-a", "--at", "136 mm", "--load", "11.4 kN", "--json", str(out), "-q"]) == 0
    capsys.readouterr()
    lin = json.loads(out.read_text())["analysis"]
    theirs = np.sort_complex(np.array([complex(*p) for p in lin["poles"]["closed_loop"]]))
    np.testing.assert_allclose(np.sort_complex(m.poles()), theirs, rtol=1e-9, atol=1e-9)
    gm, pm, _, _ = control.margin(m.loop)
    assert control.mag2db(gm) == pytest.approx(lin["figures"]["gain_margin_db_continuous"], abs=0.01)
    assert pm == pytest.approx(lin["figures"]["phase_margin_deg_continuous"], abs=0.01)
    assert control.bandwidth(m.closed_loop) / (2 * np.pi) == pytest.approx(lin["figures"]["bandwidth_hz"], rel=1e-9)
    assert control.dcgain(m.closed_loop) == pytest.approx(1.0, abs=1e-9)  # no NaN: the pole at 0 was removed
    assert np.isfinite(control.step_info(m.closed_loop)["SettlingTime"])


def test_andes_example_closes_the_gate_at_govcheck_s_move_time(capsys):
    pytest.importorskip("andes")  # a test extra (pyproject [test]); CI installs it
    ns, _ = _run("andes", capsys)
    assert ns["andes_time"] == pytest.approx(ns["govcheck_time"], rel=0.02)
    gov, a = ns["gov"], ns["a"]
    assert ns["govcheck_time"] == pytest.approx(-1.0 / gov.UC, rel=1e-9)  # the fastest closing move is UC's
    # the JSON export with the same study basis carries the same numbers (what --rating/--dispatch write)
    gov.study = {"rating_mva": 100.0, "system_mva": 100.0, "dispatch_mw": 90.0}
    assert gov.to_dict()["andes"]["HYGOV4"] == pytest.approx(a["HYGOV4"])

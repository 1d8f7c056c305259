"""The README's claims about the CLI, checked by walking the parser and by running it as a shell would."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

from compliance.cli import build_parser, main

ROOT = Path(__file__).resolve().parents[2]
SHARED = {"-q": ("--quiet", "-q"), "-j": ("--jobs", "-j"), "--reproducible": ("--reproducible",)}


def _parsers():
    """Every (sub-)command parser by its command line: 'check', 'characterise valve', ..."""
    todo, out = [("", build_parser())], {}
    while todo:
        name, parser = todo.pop()
        subs = [a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction"]
        if name:
            out[name] = parser
        for action in subs:
            todo += [(f"{name} {k}".strip(), p) for k, p in action.choices.items()]
    return out


def _takes(parser, flag):
    return next((a for a in parser._actions if flag in a.option_strings), None)


def test_shared_options_mean_the_same_everywhere():
    for name, parser in _parsers().items():
        for flag, spelling in SHARED.items():
            action = _takes(parser, flag)
            if action is None:
                continue
            assert set(action.option_strings) == set(spelling), (name, flag, action.option_strings)
            if flag == "-j":
                assert action.type is int and action.dest == "jobs" and action.default is None, name
            else:
                assert action.nargs == 0 and action.const is True and action.default is False, (name, flag)


def test_readme_lists_which_commands_take_them():
    text = " ".join((ROOT / "README.md").read_text(encoding="utf-8").split())
    claims = {}
    for flag in SHARED:
        m = re.search(rf"`{re.escape(flag)}`: ([a-z, -]+?)[;)]", text)
        assert m, f"README does not say which commands take {flag}"
        claims[flag] = {c.strip() for c in m.group(1).split(",")}
    for flag, listed in claims.items():
        actual = {n for n, p in _parsers().items() if _takes(p, flag) is not None}
        assert listed == actual, (flag, sorted(listed ^ actual))


def test_top_level_help_has_examples(capsys):
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    assert "examples:" in out and out.count("govcheck ") >= 5


def test_no_command_prints_help_and_exits_2(capsys):
    assert main([]) == 2
    err = capsys.readouterr().err
    assert "usage: govcheck" in err and "no COMMAND given" in err


def test_closed_pipe_ends_quietly():
    """``govcheck plants | head -n 1``: the reader goes away; no 'Broken pipe' error, no exit 2, nothing on stderr."""
    script = ("import os, sys; from compliance.cli import main; r, w = os.pipe(); os.close(r); os.dup2(w, 1); "
              "sys.exit(main(['plants']))")
    proc = subprocess.run([sys.executable, "-c", script], cwd=ROOT, capture_output=True, text=True,
                          env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"}, timeout=120)
    assert proc.returncode == 141, proc.stderr
    assert proc.stderr == ""

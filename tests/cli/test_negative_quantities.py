"""Negative quantities are values, in every option of every command (``--steps -5%@1s``, ``--x0 -1mm``)."""

from __future__ import annotations

import argparse

import pytest

from compliance.cli import build_parser, main


def _parsers(parser, path=()):
    """(command path, parser) of every parser and nested sub-command parser."""
    yield path, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _parsers(sub, path + (name,))


def _takes_one_value(action) -> bool:
    return bool(action.option_strings) and action.nargs in (None, "?") and not action.choices \
        and action.type in (None, str, int, float) and action.dest != "help" \
        and isinstance(action, (argparse._StoreAction, argparse._AppendAction))


def _baseline(parser, tested) -> list[str]:
    """The fewest words the parser needs besides the tested option (required positionals and options)."""
    words = []
    for action in parser._actions:
        if action is tested or isinstance(action, argparse._SubParsersAction):
            continue
        if not action.option_strings and action.nargs in (None, "+", 1):
            words.append("x")
        elif action.option_strings and action.required:
            words += [action.option_strings[0], "x.csv"]
    for group in parser._mutually_exclusive_groups:
        if group.required and tested not in group._group_actions:
            first = group._group_actions[0]
            words += [first.option_strings[0], "x"] if first.nargs != 0 else [first.option_strings[0]]
    return words


def _cases():
    for path, parser in _parsers(build_parser()):
        if any(isinstance(a, argparse._SubParsersAction) for a in parser._actions):
            continue
        for action in parser._actions:
            if _takes_one_value(action):
                yield pytest.param(path, parser, action, id=" ".join(path + (action.option_strings[-1],)))


CASES = list(_cases())
VALUE = {None: "-5%@1s", str: "-5%@1s", float: "-1e-3", int: "-5"}


def test_the_walk_sees_the_quantity_options():
    seen = {(p[0], a.option_strings[-1]) for p, _, a in (c.values for c in CASES) if p}
    assert {("simulate", "--steps"), ("simulate", "--x0"), ("simulate", "--load"), ("simulate", "--command")} <= seen
    assert len(CASES) > 40  # every command's value options, not a hand-picked few


@pytest.mark.parametrize("path,parser,action", CASES)
def test_every_value_option_takes_a_negative_quantity(path, parser, action):
    value = VALUE[action.type]
    args = parser.parse_args(_baseline(parser, action) + [action.option_strings[-1], value])
    got = getattr(args, action.dest)
    expected = action.type(value) if action.type not in (None, str) else value
    assert (got == expected) or (isinstance(got, list) and expected in got), (path, action.dest, got)


def test_simulate_negative_position_is_judged_by_govcheck_not_by_argparse(tmp_path, capsys):
    """``--x0 -1mm`` reaches the stroke check (exit 2, govcheck's message), not argparse's 'expected one argument'."""
    code = main(["simulate", "plant-a", "--x0", "-1mm", "--steps", "-5%@1s", "-o", str(tmp_path / "r.csv")])
    err = capsys.readouterr().err
    assert code == 2 and "outside the stroke" in err and "expected one argument" not in err
    assert not list(tmp_path.iterdir())

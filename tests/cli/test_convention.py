"""One CLI convention: positional CONFIG, the same option names, examples in every --help, README table = parser."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from compliance.cli import _COMMANDS, build_parser, main
from compliance.files.shipped import shipped_names

ROOT = Path(__file__).resolve().parents[2]
COMMANDS = [name for name, _ in _COMMANDS]


def _subparsers():
    parser = build_parser()
    action = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    return action.choices


@pytest.mark.parametrize("name", COMMANDS)
def test_every_help_has_examples(name, capsys):
    assert main([name, "--help"]) == 0
    text = capsys.readouterr().out
    assert "examples:" in text and f"govcheck {name}" in text.split("examples:")[1]


def test_characterise_targets_have_descriptions_and_examples(capsys):
    for target in ("valve", "friction"):
        assert main(["characterise", target, "--help"]) == 0
        text = capsys.readouterr().out
        assert "examples:" in text and len(text.split("\n\n")[1]) > 80  # a description paragraph
    assert main(["characterise", "valve", "--help"]) == 0
    assert "--volume" in capsys.readouterr().out


def test_check_help_lists_the_shipped_requirement_files(capsys):
    main(["check", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    names = shipped_names("requirements")
    assert {"iec61362", "ieee125", "iec60308", "shpp-400kw"} <= set(names)
    for n in names:
        assert n in text


def test_same_option_names_and_metavars():
    metavars = {"--json": "FILE.json", "--junit": "FILE.xml", "--report": "FILE.html", "--pdf": "FILE.pdf"}
    for name, sub in _subparsers().items():
        for action in sub._actions:
            for flag in action.option_strings:
                if flag in metavars:
                    assert action.metavar == metavars[flag], (name, flag)
                if flag == "--jobs":
                    assert "-j" in action.option_strings, name
                if flag == "--quiet":
                    assert "-q" in action.option_strings, name
    for name in ("simulate", "check", "linear", "reproduce"):
        positional = [a for a in _subparsers()[name]._actions if not a.option_strings and a.dest != "help"]
        assert positional and positional[0].metavar == "CONFIG", name


def _readme_commands():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    block = text.split("## Commands", 1)[1].split("```text", 1)[1].split("```", 1)[0]
    return [line for line in block.strip().splitlines() if line.startswith("govcheck ")]


PLACEHOLDERS = {"CONFIG": "plant-a", "CANDIDATE": "plant-a", "RECORDING": "rec.csv", "REQ": "iec61362", "N": "2",
                "ID": "IEC61362-TC", "MAP": "zillen-friction"}


@pytest.mark.parametrize("line", _readme_commands())
def test_readme_command_table_parses(line):
    """Every README command line (optional parts included) is accepted by the parser as written."""
    command = re.split(r"\s{3,}", line)[0]  # drop the description column
    command = command.replace("[", "").replace("]", "")
    tokens = [PLACEHOLDERS.get(t, t) for t in shlex.split(command)[1:]]
    try:
        args = build_parser().parse_args(tokens)
    except SystemExit as exc:  # pragma: no cover - the message is on stderr
        pytest.fail(f"README line does not parse ({exc.code}): {line}")
    assert args.command == tokens[0]


def test_readme_lists_every_command():
    listed = {line.split()[1] for line in _readme_commands()}
    assert listed == set(COMMANDS)


def test_plant_given_twice_is_an_error_not_a_choice(capsys):
    assert main(["linear", "plant-a", "--plant", "plant-b"]) == 2
    assert "two plant configurations" in capsys.readouterr().err

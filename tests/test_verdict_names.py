"""Verdict names are a type: spelt once, in ``compliance.requirements.verdict`` (requirements),
``compliance.sweep.remedies.outcome`` (remedy searches) and ``compliance.diagnosis.verdicts.verdict`` (diagnoses).

A status (``pass``, ``fail``, ``not_evaluated``, ``uncertain``), a run's overall verdict
(``incomplete``), a basis (``modelled``, ``by_construction``), a requirement's severity
(``mandatory``, ``advisory``), a remedy search's outcome (``found``, ``none_found``, ...) or a diagnosis verdict
(``missing_physics``, ``unexplained``, ...) written as a bare string in code is a second spelling
that a typo or a rename silently breaks. These read the source with ``ast``:
such a value may appear only as a *name* of something (a dict key, a subscript, the key of a
``.get``) or as a word in a table keyed by the enum members (a status's CSS class may be
``"pass"``), never as a value that is compared, returned, assigned or passed.
Templates (Jinja, not Python) are not read.
"""

from __future__ import annotations

import ast
from pathlib import Path

from compliance.diagnosis.verdicts.verdict import DiagnosisVerdict
from compliance.requirements.verdict import Basis, Overall, Severity, Status
from compliance.sweep.remedies.outcome import RemedyStatus

PACKAGE = Path(__file__).resolve().parents[1] / "compliance"
OWNERS = {PACKAGE / "requirements" / "verdict.py", PACKAGE / "diagnosis" / "verdicts" / "verdict.py",
          PACKAGE / "sweep" / "remedies" / "outcome.py"}
# words that are also plain words or other vocabularies: "open" (a limit nobody set, as text),
# "disabled", "assumed" (also a parameter source: paper / assumed / derived / user), "uncertain"
# (also a sweep file's table of uncertain parameters), "measured" (also a plot's label of the recorded trace)
SHARED_WORDS = {"open", "disabled", "assumed", "uncertain", "measured"}
VERDICT_WORDS = {m.value for enum in (Status, Overall, Basis, Severity, RemedyStatus, DiagnosisVerdict) for m in enum} - SHARED_WORDS
KEY_METHODS = {"get", "pop", "setdefault"}
ENUMS = {"Status", "Overall", "Basis", "Severity", "RemedyStatus", "DiagnosisVerdict"}


def _name_positions(tree: ast.AST) -> set[int]:
    """ids of the constant nodes that name something: dict keys, subscripts, ``.get`` keys, docstrings."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Dict):
            out.update(id(k) for k in node.keys if k is not None)
            if node.keys and all(isinstance(k, ast.Attribute) and isinstance(k.value, ast.Name)
                                 and k.value.id in ENUMS for k in node.keys):
                out.update(id(v) for v in node.values)  # a word table keyed by the members
        elif isinstance(node, ast.Subscript):
            out.add(id(node.slice))
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
              and node.func.attr in KEY_METHODS and node.args):
            out.add(id(node.args[0]))
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "key" and node.args:
            out.add(id(node.args[0]))  # a typed record's JSON key name (compliance.results.record.key)
        elif isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant):
            out.add(id(node.value))  # docstrings and bare strings
    return out


def bare_verdict_words(source: str) -> list[tuple[int, str]]:
    """(line, word) of each verdict word used as a value in ``source``."""
    tree = ast.parse(source)
    names = _name_positions(tree)
    return [(n.lineno, n.value) for n in ast.walk(tree)
            if isinstance(n, ast.Constant) and isinstance(n.value, str) and n.value in VERDICT_WORDS
            and id(n) not in names]


def test_the_checker_finds_a_bare_status_and_spares_names():
    src = ('def f(e, c):\n    """pass or fail."""\n    x = {"pass": 1}\n    y = c["fail"] + c.get("uncertain", 0)\n'
           '    if e["status"] == "fail":\n        return "incomplete"\n    return ("modelled", Status.PASS)\n'
           '    words = {Status.PASS: "pass", Basis.MODELLED: "modelled"}\n    passed: int = key("pass", default=0)\n')
    assert sorted(bare_verdict_words(src)) == [(5, "fail"), (6, "incomplete"), (7, "modelled")]


def test_no_bare_verdict_words_in_the_package():
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        if path in OWNERS:
            continue
        found += [f"{path.relative_to(PACKAGE.parent)}:{line}: {word!r}"
                  for line, word in bare_verdict_words(path.read_text())]
    assert not found, "use Status / Overall / Basis (compliance.requirements.verdict) or DiagnosisVerdict:\n" + "\n".join(found)


def test_verdict_names_serialise_as_their_json_strings():
    import json

    assert json.dumps({Status.NOT_EVALUATED: [Overall.INCOMPLETE, Basis.BY_CONSTRUCTION]}) == \
        '{"not_evaluated": ["incomplete", "by_construction"]}'
    assert f"{Status.PASS}" == "pass" and str(Basis.MODELLED) == "modelled"

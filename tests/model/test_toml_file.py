"""The one TOML reader and table check shared by plant, requirement and validation-settings files."""

import hashlib

import pytest

from compliance.errors import InputError
from compliance.model.toml_file import check_table, read_toml


def test_read_toml_returns_mapping_and_digest_of_the_bytes(tmp_path):
    path = tmp_path / "a.toml"
    raw = b'name = "x"\n[cylinder]\nstroke = "160 mm"\n'
    path.write_bytes(raw)
    data, digest = read_toml(path)
    assert data == {"name": "x", "cylinder": {"stroke": "160 mm"}}
    assert digest == hashlib.sha256(raw).hexdigest()


@pytest.mark.parametrize("raw, message", [
    (b'name = "x\n', "malformed TOML"),
    (b'name = "\xff"\n', "not a UTF-8 text file"),
])
def test_read_toml_names_the_file_and_the_problem(tmp_path, raw, message):
    path = tmp_path / "bad.toml"
    path.write_bytes(raw)
    with pytest.raises(InputError, match=message) as err:
        read_toml(path)
    assert str(err.value).startswith(f"{path}: ")


def test_read_toml_unreadable_path_is_an_input_error(tmp_path):
    with pytest.raises(InputError, match="cannot read"):
        read_toml(tmp_path)  # a folder, not a file


def test_check_table_lists_what_is_allowed():
    assert check_table({"a": 1}, "f: t", ("a", "b"), expected="a table") == {"a": 1}
    with pytest.raises(InputError, match=r"^f: t: unknown field 'c' \(expected a, b\)$"):
        check_table({"a": 1, "c": 2}, "f: t", ("a", "b"), word="field", expected="a table")
    with pytest.raises(InputError, match=r"^f: t: expected a table with a and b$"):
        check_table([1], "f: t", ("a", "b"), expected="a table with a and b")

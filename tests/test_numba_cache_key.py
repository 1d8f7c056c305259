"""The numba cache folder is keyed by every compiled source (compliance/__init__.py): a kernel edited in
one module and inlined into another must never run from a stale cache."""

from pathlib import Path

import compliance

PACKAGE = Path(compliance.__file__).resolve().parent


def test_every_module_with_compiled_code_is_in_the_cache_key():
    compiled = [p.relative_to(PACKAGE) for p in PACKAGE.rglob("*.py")
                if "@njit" in p.read_text(encoding="utf-8") and p.parent != PACKAGE]
    assert compiled, "no compiled module found: the search itself is wrong"
    outside = [str(p) for p in compiled if p.parts[0] not in compliance._COMPILED_STAGES]
    assert not outside, f"compiled code outside the folders the numba cache key reads: {outside}"


def test_the_cache_folder_follows_the_sources(tmp_path, monkeypatch):
    """A changed compiled source (here: a copy of the package with one kernel file edited) moves the folder."""
    import shutil

    copy = tmp_path / "compliance"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(compliance, "__file__", str(copy / "__init__.py"))
    before = compliance._numba_cache_dir()
    laws = copy / "diagnosis" / "friction_bench" / "laws.py"  # a room inside a stage
    laws.write_text(laws.read_text(encoding="utf-8") + "\n# edited\n", encoding="utf-8")
    assert compliance._numba_cache_dir() != before

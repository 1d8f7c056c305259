"""The numba cache folder is keyed by every compiled source (compliance/__init__.py): a kernel edited in
one module and inlined into another must never run from a stale cache, and an edit to code that is not
compiled must not recompile the core."""

import shutil
from pathlib import Path

import compliance

PACKAGE = Path(compliance.__file__).resolve().parent


def _copy(tmp_path, monkeypatch) -> Path:
    copy = tmp_path / "compliance"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(compliance, "__file__", str(copy / "__init__.py"))
    return copy


def _edit(path: Path) -> None:
    path.write_text(path.read_text(encoding="utf-8") + "\n# edited\n", encoding="utf-8")


def test_every_module_with_compiled_code_is_in_the_cache_key():
    compiled = {p for p in PACKAGE.rglob("*.py") if "@njit" in p.read_text(encoding="utf-8")}
    assert any(p.parts[-3:-1] == ("diagnosis", "friction_bench") for p in compiled)  # a kernel outside the core
    assert compiled <= set(compliance._compiled_sources(PACKAGE))


def test_an_edited_kernel_moves_the_cache_folder(tmp_path, monkeypatch):
    copy = _copy(tmp_path, monkeypatch)
    before = compliance._numba_cache_dir()
    _edit(copy / "diagnosis" / "friction_bench" / "laws.py")  # a kernel in a room inside a stage
    after_laws = compliance._numba_cache_dir()
    _edit(copy / "physics" / "friction.py")  # a core kernel inlined elsewhere
    assert len({before, after_laws, compliance._numba_cache_dir()}) == 3


def test_an_edit_outside_the_compiled_code_keeps_the_cache_folder(tmp_path, monkeypatch):
    copy = _copy(tmp_path, monkeypatch)
    before = compliance._numba_cache_dir()
    _edit(copy / "diagnosis" / "servo" / "selection.py")
    assert compliance._numba_cache_dir() == before

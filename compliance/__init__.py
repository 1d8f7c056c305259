"""govcheck: acceptance harness for pneumatic gate servo-positioners (package ``compliance``)."""

import hashlib as _hashlib
import os as _os
from pathlib import Path as _Path

from compliance.version import __version__


_COMPILED_STAGES = ("physics", "effects", "model", "simulation")  # the compiled core and the slot layout it freezes


def _compiled_sources(here: _Path) -> list:
    """Every source the compiled code is built from: the core's stages whole, and any other module with a kernel."""
    core = [f for sub in _COMPILED_STAGES for f in sorted((here / sub).rglob("*.py"))]
    others = [f for f in sorted(here.rglob("*.py"))
              if f.relative_to(here).parts[0] not in _COMPILED_STAGES and b"@njit" in f.read_bytes()]
    return core + others


def _numba_cache_dir() -> str:
    """A numba cache folder keyed by the compiled sources.

    numba invalidates a cached function only when its own file changes, not when a kernel it
    inlines from another module does; keying the folder by every compiled source avoids ever
    running a stale core (and an edit elsewhere does not recompile it).
    """
    here = _Path(__file__).resolve().parent
    digest = _hashlib.sha256()
    for f in _compiled_sources(here):
        digest.update(f.read_bytes())
    return str(here / "__pycache__" / f"numba-{digest.hexdigest()[:16]}")


if "NUMBA_CACHE_DIR" not in _os.environ:
    try:
        _os.environ["NUMBA_CACHE_DIR"] = _numba_cache_dir()
    except OSError:  # read-only install: numba falls back to its own default
        pass

# govcheck runs in parallel over processes (compliance.processes); inside each, OpenBLAS's own threads
# only spin-wait on the small least-squares matrices of a fit, doubling CPU time for no gain and
# stealing the other worker's core. One BLAS thread per process unless the user chose otherwise
# (read when numpy loads, so it must be set before the first numpy import).
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    _os.environ.setdefault(_var, "1")

__all__ = ["CheckResult", "__version__", "check"]


def __getattr__(name: str):
    """``compliance.check`` and ``compliance.CheckResult``, imported on first use (``import compliance`` stays light:
    every worker process imports the package)."""
    if name == "check":
        from compliance.pipeline.chain import check

        return check
    if name == "CheckResult":
        from compliance.results.check_result import CheckResult

        return CheckResult
    raise AttributeError(f"module 'compliance' has no attribute {name!r}")

"""Test-bench recordings: one reader per format, column maps, sidecar metadata, synthesis.
:func:`read_recording` returns the canonical frame (SI, absolute pressures) and its metadata."""

from compliance.recordings.reader import *  # noqa: F401,F403
from compliance.recordings.reader import __all__  # noqa: F401

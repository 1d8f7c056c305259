"""Test procedures: one module per procedure kind, the kinds declared as data, and the registry
that runs a procedure at an operating point (:func:`run`)."""

from compliance.procedures.registry import *  # noqa: F401,F403
from compliance.procedures.registry import __all__  # noqa: F401

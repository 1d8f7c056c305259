"""Requirement files: schema, entries, inheritance and tightening, frozen requirement objects,
and a measured value judged against a limit (:mod:`compliance.requirements.verdict`)."""

from compliance.requirements.loading import *  # noqa: F401,F403
from compliance.requirements.loading import __all__  # noqa: F401

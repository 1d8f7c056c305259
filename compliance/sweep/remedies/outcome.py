"""What a remedy search concludes about a configuration, spelt once (the ``status`` of ``remedies`` in the results)."""

from __future__ import annotations

from enum import StrEnum


class RemedyStatus(StrEnum):
    """Outcome of ``smallest_change.find_remedy`` / ``staged_search`` (and of judging the configuration as given)."""

    ALREADY_PASSES = "already_passes"  # every mandatory requirement passes as given: nothing to change
    FAILS = "fails"  # the configuration as given fails (before any search)
    FOUND = "found"  # a change that passes, verified by a full campaign
    NONE_FOUND = "none_found"  # nothing judged passes: the closest candidate and what binds it are reported


__all__ = ["RemedyStatus"]

"""Spelling help for error messages: the closest known name to one the user wrote."""

from __future__ import annotations

import difflib

__all__ = ["did_you_mean"]


def did_you_mean(word, choices) -> str:
    """``"; did you mean 'stribeck'?"`` for the closest of ``choices`` to ``word``, else ``""``.

    Parameters
    ----------
    word : object
        What the user wrote (compared as text).
    choices : iterable
        Known names (compared as text; a dict gives its keys).
    """
    close = difflib.get_close_matches(str(word), [str(c) for c in choices], n=1)
    return f"; did you mean '{close[0]}'?" if close else ""

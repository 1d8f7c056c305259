"""Error types that the CLI maps to exit codes (2 = bad input), and the spelling help their messages use."""

import difflib


class GovcheckError(Exception):
    """Base class for every error govcheck reports to a user without a traceback."""

    exit_code = 2


class InputError(GovcheckError):
    """Invalid user input: a file, a field, a unit, a value. Exit code 2.

    The message must name the file (and key path, row or column) and say what was expected.
    """


class SimulationError(GovcheckError):
    """The solver diverged or produced non-finite states. Exit code 2."""


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

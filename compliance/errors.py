"""Error types that the CLI maps to exit codes (2 = bad input)."""


class GovcheckError(Exception):
    """Base class for every error govcheck reports to a user without a traceback."""

    exit_code = 2


class InputError(GovcheckError):
    """Invalid user input: a file, a field, a unit, a value. Exit code 2.

    The message must name the file (and key path, row or column) and say what was expected.
    """


class SimulationError(GovcheckError):
    """The solver diverged or produced non-finite states. Exit code 2."""

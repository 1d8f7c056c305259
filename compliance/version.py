"""The version of govcheck (one place: the package re-exports it, results and reports record it)."""

__version__ = "0.1.0"

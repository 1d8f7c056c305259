"""govcheck: acceptance harness for pneumatic gate servo-positioners (package ``compliance``)."""

__version__ = "0.1.0"

__all__ = ["__version__"]

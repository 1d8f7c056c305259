"""Model validation against a recording: replay, locate the mismatch, regimes, fit measures."""

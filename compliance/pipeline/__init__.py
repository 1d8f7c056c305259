"""The composing room: ``compliance.check`` runs the public steps of a check and returns a typed result."""

from compliance.pipeline.chain import Check, bands, campaign, check, judgement, linear_analysis, remedy_search, vet

__all__ = ["Check", "bands", "campaign", "check", "judgement", "linear_analysis", "remedy_search", "vet"]

"""Diagnosis of seal-friction force-bench runs: friction laws fitted, proved out of sample, explained.

``runs`` (the runs), ``laws`` / ``position`` (friction laws as functions of the measured motion),
``fit`` (one law fitted), ``holdout`` (out-of-sample proof), ``residual_structure`` (what the best law
leaves), ``explanation`` (the paragraph), ``diagnose`` (the chain: ``diagnose_friction``).
"""

"""Candidate sweeps, remedies and tolerance yield above the campaign (docs/scaling.md).

``spec`` reads sweep files, ``sampling`` draws candidates and units, ``evaluate`` judges them
in workers, ``runner`` batches them on the one executor (``compliance.campaign.executor``),
``results`` tabulates, ``remedies`` searches the smallest passing change, ``yield_mc`` runs
the tolerance Monte Carlo, ``run`` writes the outputs.
"""

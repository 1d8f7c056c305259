"""The diagnosis scored against known answers: generated cases and practice recordings.

``concealed_cases`` (one concealed effect per generated case), ``two_effect_cases`` (two effects at
once and structural variety), ``benchmark`` (the scored run: ``govcheck diagnose-benchmark``),
``practice_score`` (recordings with answers).
"""

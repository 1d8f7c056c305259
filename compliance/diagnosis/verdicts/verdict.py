"""What a diagnosis concludes about a recording, spelt once (the ``verdict`` of docs/diagnosis-schema.md).

Shared by the closed-loop servo diagnosis (one recording or several jointly) and the
friction-bench diagnosis; reports and the benchmark read the same names.
"""

from __future__ import annotations

from enum import StrEnum

__all__ = ["DiagnosisVerdict", "EXPLAINED", "INCOMPLETE"]


class DiagnosisVerdict(StrEnum):
    """A diagnosis verdict, as written in its JSON."""

    NO_MISMATCH = "no_mismatch"  # the model meets the recording within its noise
    MISSING_PHYSICS = "missing_physics"  # a declared effect (or set of effects) explains the mismatch
    PARAMETERS_ONLY = "parameters_only"  # recalibrated base parameters explain it: no physics missing
    PARTIALLY_EXPLAINED = "partially_explained"  # an explanation, but signals are left above their floors
    AMBIGUOUS = "ambiguous"  # the recording cannot tell the best explanations apart
    UNEXPLAINED = "unexplained"  # nothing declared explains enough of the mismatch
    INSTRUMENTATION = "instrumentation"  # a logger or transducer finding, not the plant


# an explanation was found (the winner's fit is the answer)
EXPLAINED = (DiagnosisVerdict.MISSING_PHYSICS, DiagnosisVerdict.PARAMETERS_ONLY)
# the search ended without a complete explanation (the friction form and the empirical term are tried)
INCOMPLETE = (DiagnosisVerdict.UNEXPLAINED, DiagnosisVerdict.PARTIALLY_EXPLAINED)

"""Requirement limits checked against the physical sign of their metric.

Every metric of the catalogue (times, errors, speeds, amplitudes, fractions, counts) is a
magnitude: it cannot be negative. A limit below zero (``time_constant <= -1 s``) can then
never pass, or always passes, whatever the plant does - it is a typo, not a requirement.
"""

from __future__ import annotations

from compliance.errors import InputError

__all__ = ["SIGNED_METRICS", "check_limit_signs"]

SIGNED_METRICS: frozenset[str] = frozenset()  # metrics that may be negative (none in the catalogue today)


def check_limit_signs(requirements, origin: dict) -> None:
    """Refuse a negative limit on a metric that cannot be negative.

    Parameters
    ----------
    requirements : iterable of Requirement
        Built requirements (limits as :class:`~compliance.units.amounts.Amount`).
    origin : dict
        (section, name, key) -> file that set it, for the message.

    Raises
    ------
    InputError
        Naming the file, the requirement's ``limit`` key, the value and what was expected.
    """
    for req in requirements:
        if req.limit is None or req.metric in SIGNED_METRICS:
            continue
        for amount in req.limit:
            if amount.value < 0:
                where = origin.get(("requirements", req.id, "limit"), req.defined_in)
                raise InputError(
                    f"{where}: requirements.{req.id}.limit: {amount.text} is negative, but '{req.metric}' is a "
                    f"magnitude (never below 0), so '{req.comparator} {amount.text}' could never be decided by the "
                    "plant; expected a limit >= 0"
                )

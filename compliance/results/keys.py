"""A metric request as a tuple: the metric and its options as written (``time_constant[detect=1 %stroke]``).

Runs measure every metric a requirement asks for with the options it names; the request is the
key of the run's values and of the requirement's rows. Inside a result it is a ``RequestKey``
(``key.metric``, ``key.options``); its text form, the key of the results JSON, is written by
``str(key)`` and read by :meth:`RequestKey.parse`, at the edge only.
"""

from __future__ import annotations

from typing import NamedTuple

__all__ = ["RequestKey"]


class RequestKey(NamedTuple):
    """``(metric, ((option, value as written), ...))``, options sorted by name."""

    metric: str
    options: tuple[tuple[str, str], ...] = ()

    @classmethod
    def of(cls, metric: str, options: dict | None = None) -> "RequestKey":
        """The key of ``metric`` with a requirement's options (values as written, ``Amount`` or plain)."""
        pairs = tuple((str(k), str(v.text if hasattr(v, "text") else v)) for k, v in sorted((options or {}).items()))
        return cls(metric, pairs)

    @classmethod
    def parse(cls, text: str) -> "RequestKey":
        """The key of its text form (``metric`` or ``metric[a=1,b=2 mm]``): the one reader of that form."""
        text = str(text)
        metric, bracket, rest = text.partition("[")
        if not bracket:
            return cls(metric)
        pairs: list[list[str]] = []
        for part in rest[:-1].split(",") if rest.endswith("]") else rest.split(","):
            name, eq, value = part.partition("=")
            if eq or not pairs:
                pairs.append([name, value])
            else:  # a comma inside a value as written
                pairs[-1][1] += "," + part
        return cls(metric, tuple((a, b) for a, b in pairs))

    def __str__(self) -> str:
        if not self.options:
            return self.metric
        return self.metric + "[" + ",".join(f"{k}={v}" for k, v in self.options) + "]"

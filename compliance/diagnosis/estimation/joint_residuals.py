"""Several recordings' residuals as one fit objective: each recording replayed with its own conditions, one
parameter set for all (``diagnosis.servo.joint_recordings``).

``JointModel`` stacks the recordings' residual models (signal blocks labelled ``recording:signal``);
``JointContext`` evaluates one parameter set on every recording's fit context (``servo.fit.FitContext``),
one after the other, and stops at the first recording whose residual already decides.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass
class JointModel:
    """The residual models of several recordings as one: signal blocks labelled ``recording:signal``."""

    parts: list
    labels: list

    @property
    def size(self) -> int:
        """Length of the stacked residual vector."""
        return int(sum(p.size for p in self.parts))

    @property
    def signals(self) -> tuple:
        """Block labels ``label:signal``, in vector order."""
        return tuple(f"{lab}:{s}" for lab, p in zip(self.labels, self.parts) for s in p.signals)

    @property
    def block_sizes(self) -> list:
        """Length of each block (a signal of one recording), for the per-block autocorrelation of ``servo.fit``."""
        return [p.index.size for p in self.parts for _ in p.signals]

    @property
    def index(self) -> np.ndarray:
        """The first recording's fitted samples (only their spacing is read: ``servo.fit.HAC_SECONDS`` in samples)."""
        return self.parts[0].index

    def split(self, vec: np.ndarray) -> dict:
        """Block label -> its part of a residual vector."""
        out, start = {}, 0
        for lab, m in zip(self.signals, self.block_sizes):
            out[lab] = vec[start:start + m]
            start += m
        return out


@dataclass
class JointContext:
    """What every joint fit shares: one ``FitContext`` per recording (its own configuration, replay, floors)."""

    contexts: list
    labels: list
    sims: int = 0
    stopped: bool = False  # the last ``residual`` did not replay every recording in full
    order: list | None = None  # recordings in the order they are replayed (``residual``)

    @property
    def model(self) -> JointModel:
        """The stacked residual model."""
        return JointModel([c.model for c in self.contexts], self.labels)

    @property
    def setup(self):
        """The first recording's replay (its time base gives the residual spacing)."""
        return self.contexts[0].setup

    @property
    def cfg(self) -> PlantConfig:
        """The first recording's configuration (nominal values of recalibrated parameters)."""
        return self.contexts[0].cfg

    def residual(self, params, values, limit: float = math.inf) -> tuple[np.ndarray, list | None]:
        """Stacked normalised residuals of one shared parameter set (each recording replayed with its conditions).

        With a finite ``limit`` on their sum of squares (``servo.fit.FitContext.residual``) the recordings are
        replayed one after the other against what the limit leaves, and those after the one that
        exceeds it are not replayed (their residuals are zero; ``stopped`` says so). They are replayed
        in the order of their share of the first full evaluation, largest first (where a worse candidate
        shows soonest); the vector keeps the recordings' order.
        """
        n = len(self.contexts)
        vecs, sims = [None] * n, [None] * n
        chi2 = 0.0
        self.stopped = False
        for i in self.order or range(n):
            c = self.contexts[i]
            if self.stopped:
                vecs[i] = np.zeros(c.model.size)
                continue
            v, s = c.residual(params, values, limit - chi2)
            chi2 += float(np.dot(v, v))
            self.sims += 1
            self.stopped = c.stopped or chi2 > limit
            vecs[i], sims[i] = v, s
        if self.order is None and not self.stopped:
            self.order = sorted(range(n), key=lambda i: -float(np.dot(vecs[i], vecs[i])))
        return np.concatenate(vecs), (None if any(s is None for s in sims) else sims)


__all__ = ["JointContext", "JointModel"]

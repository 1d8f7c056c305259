"""Test helper: run a reduced-order observer over sampled signals in Python (the loop's update).

It checks the compiled observer step (``compliance.model.observers.observer_foh_step``) against
exact discretisations in ``test_tracking.py``; the simulator runs the same step inside its loop.
"""

from __future__ import annotations

import numpy as np

from compliance.model.observers import observer_foh_step


def observe(observer, measured, inputs, sample_time, initial=0.0):
    """Run a reduced-order observer over sampled signals (the loop's update, in Python).

    Parameters
    ----------
    observer : design.ReducedObserver
    measured : array_like
        (n, m) measured states x1 per sample (m = number of measured states).
    inputs : array_like
        (n,) input per sample, held from sample k to k+1 (the valve command, or u_p).
    sample_time : float
        [s].
    initial : float
        Estimate at the first sample.

    Returns
    -------
    ndarray
        (n,) estimates x2^ = w + L x1.
    """
    x1 = np.atleast_2d(np.asarray(measured, float))
    if x1.shape[0] == 1 and x1.shape[1] != 1:
        x1 = x1.T
    u = np.asarray(inputs, float)
    L = np.asarray(observer.gain, float)
    sg = np.asarray(observer.state_gain, float)
    ig = float(observer.input_gain[0])
    n = x1.shape[0]
    est = np.zeros(n)
    w = initial - float(L @ x1[0])
    est[0] = initial
    for k in range(1, n):
        d0 = ig * u[k - 1] + float(sg @ x1[k - 1])
        d1 = ig * u[k - 1] + float(sg @ x1[k])
        w = observer_foh_step(w, observer.pole, d0, d1, sample_time)
        est[k] = w + float(L @ x1[k])
    return est

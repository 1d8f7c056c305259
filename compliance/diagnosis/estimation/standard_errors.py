"""Standard errors of a least-squares fit to replay residuals: the Newey-West sandwich.

Standard errors come from the final Jacobian J and the residuals r themselves: the
heteroscedasticity-and-autocorrelation-consistent sandwich of Newey & West (1987),
cov = (J^T J)^-1 S (J^T J)^-1 with S = sum over lags |l| <= L of (1 - |l|/(L+1)) sum_t g_t g_(t-l)^T,
g_t = J_t r_t. A replay's misfit is not white noise: one breakaway the replay makes and the bench
did not leaves a burst correlated over a second, and such bursts carry far less information than as
many independent samples. S is never taken below J^T J (the floors' own noise level).
"""

from __future__ import annotations

import numpy as np


def hac_information(jac_data: np.ndarray, vec: np.ndarray, model, lag: int) -> np.ndarray:
    """Newey-West (1987) estimate of the residual scores' covariance S, per signal block.

    Parameters
    ----------
    jac_data : ndarray (n, k)
        Jacobian rows of the data residuals.
    vec : ndarray (n,)
        Data residuals (normalised).
    model : ResidualModel
        Gives the per-signal blocks (each a time series).
    lag : int
        Bandwidth L in residual samples (Bartlett weights 1 - l/(L + 1)).
    """
    k = jac_data.shape[1]
    s = np.zeros((k, k))
    # one block per signal; a joint model of several recordings (servo/joint_recordings.py) has blocks of its own lengths
    sizes = getattr(model, "block_sizes", None) or [model.index.size] * len(model.signals)
    start = 0
    for m in sizes:
        g = jac_data[start:start + m] * vec[start:start + m, None]
        start += m
        s += g.T @ g
        for lg in range(1, min(lag, m - 1) + 1):
            c = g[lg:].T @ g[:-lg]
            s += (1.0 - lg / (lag + 1.0)) * (c + c.T)
    return s


def fit_errors(params, values, jac, n, model, vec, lag: int) -> tuple[list[float], np.ndarray]:
    """Standard errors [SI] and the covariance [SI] of the fitted values (Newey-West sandwich)."""
    k = len(params)
    jd, jp = jac[:n], jac[n:]  # data rows, prior rows (independent, unit variance)
    try:
        a_inv = np.linalg.pinv(jac.T @ jac)
        s = hac_information(jd, vec, model, lag)
        plain = jd.T @ jd
        if np.trace(s) < np.trace(plain):
            s = s * (np.trace(plain) / max(np.trace(s), 1e-300))  # never below the floors' noise
        cov = a_inv @ (s + jp.T @ jp) @ a_inv
    except np.linalg.LinAlgError:
        cov = np.full((k, k), np.inf)
    su = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    d = np.array([fp.stderr(v, 1.0) for fp, v in zip(params, values)])  # dvalue/du (linear in sigma_u)
    return [fp.stderr(v, float(x)) for fp, v, x in zip(params, values, su)], cov * np.outer(d, d)


__all__ = ["fit_errors", "hac_information"]

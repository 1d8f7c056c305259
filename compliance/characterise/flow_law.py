"""Fit and rank valve flow laws against measured mass flow.

The laws are the simulator's own scalar kernels in ``compliance.physics.valve_flow`` (so a fitted
coefficient means exactly what the simulator uses), vectorised here with ``numpy.vectorize``:

- ``iso6358``    q = C p1 rho0 sqrt(T0/T1) w(p2/p1; b)          seed 000 eqs. (1)-(2)
- ``sanville``   q = A_e p1/sqrt(T1) psi(p2/p1)                  seed 001 eq. (5)
- ``bobrow``     q = C_f A sqrt(p1 - p2)                         seed 001 eq. (6)
- ``power``      q = C_f1 (p1 - p2)^lambda, lambda free         seed 001 eq. (7), lost in the text
- ``power-0.25`` q = C_f1 (p1 - p2)^0.25 + C_f2 (p1 - p2)        seed 001 eq. (7) with lambda = 0.25

Seed 001's eq. (7) is lost in the extracted text: only "C_f1 and C_f2 are experimental
coefficients, lambda = 0.25" survives, so the power law's form is our assumption.
The opening is folded into the coefficients (a recording is taken at one command): the
fitted ``conductance`` is C * A_re(u), ``area`` is A(u), ``coefficient`` is C_f * A(u).

Every law is linear in its coefficients once its shape parameter (b or lambda) is fixed, so
each fit is a one-dimensional search over the shape parameter with the coefficients solved
by linear least squares at every trial (variable projection, Golub & Pereyra 1973).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize_scalar

from compliance.errors import InputError
from compliance.physics import valve_flow as _vf

GAMMA = 1.4  # heat capacity ratio of air (reference-plant.md)
R_AIR = 287.0  # gas constant of air [J/(kg*K)] (reference-plant.md)
RHO0 = 1.204  # density at NTP [kg/m^3], seed 000 footnote 1
T0 = 293.15  # temperature at NTP [K], seed 000 footnote 1

_iso = np.vectorize(_vf.iso6358_mass_flow, otypes=[float])
_sanville = np.vectorize(_vf.sanville_mass_flow, otypes=[float])
_bobrow = np.vectorize(_vf.bobrow_mass_flow, otypes=[float])
_power = np.vectorize(_vf.power_law_mass_flow, otypes=[float])


def iso6358_mass_flow(p_up, p_down, t_up, conductance, critical_ratio, rho0=RHO0, t0=T0):
    """ISO 6358 mass flow, seed 000 eqs. (1)-(2), vectorised [kg/s].

    Parameters
    ----------
    p_up, p_down : array_like
        Absolute upstream / downstream pressures [Pa].
    t_up : array_like
        Upstream temperature [K].
    conductance : float
        Sonic conductance times relative opening [m^3/(s*Pa)].
    critical_ratio : float
        b [-].
    rho0, t0 : float
        Reference density [kg/m^3] and temperature [K].
    """
    return _iso(1.0, conductance, p_up, p_down, t_up, critical_ratio, rho0, t0)


def sanville_mass_flow(p_up, p_down, t_up, area, gamma=GAMMA, r_gas=R_AIR):
    """Sanville (1971) ideal-orifice mass flow, seed 001 eq. (5), vectorised [kg/s].

    ``area`` is the effective flow area [m^2]; pressures [Pa abs]; ``t_up`` [K].
    """
    return _sanville(area, p_up, p_down, t_up, gamma, r_gas)


def bobrow_mass_flow(p_up, p_down, coefficient):
    """Bobrow & McDonell (1998) mass flow q = C_f A sqrt(p_up - p_down), seed 001 eq. (6) [kg/s].

    ``coefficient`` is C_f * A(u) [kg/(s*Pa^0.5)]; pressures [Pa abs].
    """
    return _bobrow(coefficient, 1.0, p_up, p_down)


def power_law_mass_flow(p_up, p_down, cf1, exponent=0.25, cf2=0.0):
    """Empirical power law q = C_f1 dp^lambda + C_f2 dp (seed 001 eq. (7), assumed form) [kg/s].

    ``cf1`` [kg/(s*Pa^lambda)], ``cf2`` [kg/(s*Pa)], ``exponent`` lambda [-]; pressures [Pa abs].
    """
    return _power(cf1, cf2, exponent, 1.0, p_up, p_down)


@dataclass(frozen=True)
class _Law:
    name: str
    equation: str
    linear: tuple[tuple[str, str], ...]  # (parameter, unit) solved by linear least squares
    shape: tuple[str, str, float, float] | None  # (parameter, unit, lower, upper) searched in 1-D
    basis: object  # (shape value, p_up, p_down, t_up) -> (n, k) matrix


LAWS = {
    "iso6358": _Law(
        "iso6358", "q = C p1 rho0 sqrt(T0/T1) w(p2/p1; b)  [seed 000 eqs. 1-2]",
        (("conductance", "m^3/(s*Pa)"),), ("critical_ratio", "-", 0.02, 0.98),
        lambda b, pu, pd, tu: iso6358_mass_flow(pu, pd, tu, 1.0, b)[:, None],
    ),
    "sanville": _Law(
        "sanville", "q = A_e p1/sqrt(T1) psi(p2/p1)  [seed 001 eq. 5]",
        (("area", "m^2"),), None,
        lambda _, pu, pd, tu: sanville_mass_flow(pu, pd, tu, 1.0)[:, None],
    ),
    "bobrow": _Law(
        "bobrow", "q = C_f A sqrt(p1 - p2)  [seed 001 eq. 6]",
        (("coefficient", "kg/(s*Pa^0.5)"),), None,
        lambda _, pu, pd, tu: bobrow_mass_flow(pu, pd, 1.0)[:, None],
    ),
    "power": _Law(
        "power", "q = C_f1 (p1 - p2)^lambda  [seed 001 eq. 7 lost; assumed form, lambda free]",
        (("cf1", "kg/(s*Pa^lambda)"),), ("exponent", "-", 0.05, 1.5),
        lambda lam, pu, pd, tu: power_law_mass_flow(pu, pd, 1.0, lam)[:, None],
    ),
    "power-0.25": _Law(
        "power-0.25", "q = C_f1 (p1 - p2)^0.25 + C_f2 (p1 - p2)  [seed 001 eq. 7 lost; lambda = 0.25 as printed]",
        (("cf1", "kg/(s*Pa^0.25)"), ("cf2", "kg/(s*Pa)")), None,
        lambda _, pu, pd, tu: np.column_stack(
            (power_law_mass_flow(pu, pd, 1.0, 0.25), power_law_mass_flow(pu, pd, 0.0, 0.25, 1.0))
        ),
    ),
}


@dataclass(frozen=True)
class FlowFit:
    """One fitted flow law: parameters in SI with standard errors, residual and AIC."""

    law: str
    equation: str
    params: dict
    stderr: dict
    units: dict
    rms: float  # residual root mean square [kg/s]
    aic: float  # n_eff*ln(RSS/n) + 2k (lower is better)
    n: int
    n_eff: float
    extra: dict = field(default_factory=dict)
    implausible: str | None = None  # why the fitted values are physically impossible (never ranked best)

    def predict(self, p_up, p_down, t_up):
        """Mass flow of this fit at the given pressures [Pa abs] and temperature [K] [kg/s]."""
        law = LAWS[self.law]
        shape = self.params[law.shape[0]] if law.shape else None
        coefs = np.array([self.params[name] for name, _ in law.linear])
        pu, pd, tu = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (p_up, p_down, t_up)))
        return law.basis(shape, pu.ravel(), pd.ravel(), tu.ravel()) @ coefs


def _solve(law: _Law, shape, pu, pd, tu, q):
    basis = law.basis(shape, pu, pd, tu)
    coefs, *_ = np.linalg.lstsq(basis, q, rcond=None)
    resid = q - basis @ coefs
    return coefs, float(resid @ resid), basis


def fit_flow_law(name: str, p_up, p_down, t_up, mass_flow, *, correlation_length: float = 1.0, flow_noise=None) -> FlowFit:
    """Fit one flow law by least squares on mass flow.

    Parameters
    ----------
    name : str
        One of ``LAWS``.
    p_up, p_down : array_like
        Absolute pressures [Pa] up- and downstream of the valve.
    t_up : array_like
        Upstream gas temperature [K].
    mass_flow : array_like
        Measured mass flow [kg/s].
    correlation_length : float
        Samples per independent observation (the derivative window): AIC counts
        ``n / correlation_length`` observations, because a smoothed derivative's residuals
        are not independent from sample to sample.
    flow_noise : (idx, weights, sigma), optional
        The mass-flow noise as a linear map of white sensor noise of std ``sigma``:
        noise_i = sum_j weights[i, j] * e[idx[i, j]]. If given, standard errors are this noise
        propagated through the (linearised) fit; otherwise the ordinary least-squares
        estimate s^2 (J^T J)^-1, which assumes independent residuals.

    Returns
    -------
    FlowFit
    """
    if name not in LAWS:
        raise InputError(f"flow law '{name}' not known; known: {', '.join(LAWS)}")
    law = LAWS[name]
    pu, pd, tu, q = (np.asarray(a, dtype=float).ravel() for a in np.broadcast_arrays(p_up, p_down, t_up, mass_flow))
    n = q.size
    k = len(law.linear) + (1 if law.shape else 0)
    if n <= k + 1:
        raise InputError(f"flow law '{name}': {n} usable samples, need more than {k + 1}")
    shape = None
    if law.shape:
        lo, hi = law.shape[2], law.shape[3]
        grid = np.linspace(lo, hi, 33)
        rss = [_solve(law, s, pu, pd, tu, q)[1] for s in grid]
        j = int(np.argmin(rss))
        a, b = grid[max(j - 1, 0)], grid[min(j + 1, grid.size - 1)]
        res = minimize_scalar(lambda s: _solve(law, s, pu, pd, tu, q)[1], bounds=(a, b), method="bounded",
                              options={"xatol": 1e-6 * (hi - lo)})
        shape = float(res.x)
    coefs, rss, basis = _solve(law, shape, pu, pd, tu, q)
    jac = basis
    if law.shape:
        h = 1e-5 * (law.shape[3] - law.shape[2])
        dq = (law.basis(shape + h, pu, pd, tu) - law.basis(shape - h, pu, pd, tu)) @ coefs / (2 * h)
        jac = np.column_stack((basis, dq))
    se = _stderr(jac, rss, flow_noise)
    names = [p for p, _ in law.linear] + ([law.shape[0]] if law.shape else [])
    units = dict(law.linear + ((law.shape[:2],) if law.shape else ()))
    values = list(map(float, coefs)) + ([shape] if law.shape else [])
    n_eff = n / correlation_length
    aic = n_eff * math.log(max(rss, 1e-300) / n) + 2 * k  # Akaike (1974), Gaussian residuals
    params = dict(zip(names, values))
    return FlowFit(
        law=name, equation=law.equation, params=params, stderr=dict(zip(names, map(float, se))),
        units=units, rms=math.sqrt(rss / n), aic=aic, n=n, n_eff=n_eff, implausible=implausibility(name, params),
    )


# the flow through a valve goes from high to low pressure: its conductance, area or coefficient is > 0
_POSITIVE = {"iso6358": ("conductance",), "sanville": ("area",), "bobrow": ("coefficient",), "power": ("cf1",),
             "power-0.25": ("cf1",)}
_NON_NEGATIVE = {"power-0.25": ("cf2",)}


def implausibility(name: str, params: dict) -> str | None:
    """Why a fitted law is physically impossible (a conductance or area <= 0), or None when it is plausible."""
    bad = [f"{k} = {params[k]:.3g}" for k in _POSITIVE.get(name, ()) if not params[k] > 0]
    bad += [f"{k} = {params[k]:.3g}" for k in _NON_NEGATIVE.get(name, ()) if not params[k] >= 0]
    return f"{', '.join(bad)} (must be positive: flow goes from high to low pressure)" if bad else None


def _stderr(jac: np.ndarray, rss: float, flow_noise) -> np.ndarray:
    n, k = jac.shape
    try:
        pinv = np.linalg.solve(jac.T @ jac, jac.T)  # (k, n): linearised parameter sensitivity
    except np.linalg.LinAlgError:
        return np.full(k, np.inf)
    if flow_noise is None:
        return np.sqrt(np.clip(np.sum(pinv**2, axis=1) * rss / (n - k), 0.0, None))
    idx, weights, sigma = flow_noise
    size = int(idx.max()) + 1
    sens = np.array([np.bincount(idx.ravel(), (pinv[r][:, None] * weights).ravel(), minlength=size) for r in range(k)])
    return sigma * np.sqrt(np.sum(sens**2, axis=1))  # linear propagation of white sensor noise


def rank_flow_laws(p_up, p_down, t_up, mass_flow, laws=tuple(LAWS), *, correlation_length: float = 1.0, flow_noise=None):
    """Fit every law in ``laws`` and return the fits sorted by AIC (best first), physically impossible fits last.

    Raises
    ------
    InputError
        No law gives physically possible values (e.g. a negative conductance: the recording is
        not a charging or discharging test of the volume through the valve).
    """
    fits = [
        fit_flow_law(n, p_up, p_down, t_up, mass_flow, correlation_length=correlation_length, flow_noise=flow_noise)
        for n in laws
    ]
    if all(f.implausible for f in fits):
        worst = "; ".join(f"{f.law}: {f.implausible}" for f in fits)
        raise InputError(f"no flow law fits with physically possible values ({worst}); the pressure does not behave "
                         "like a fixed volume charged or discharged through the valve - is this a charging test?")
    return sorted(fits, key=lambda f: (f.implausible is not None, f.aic))

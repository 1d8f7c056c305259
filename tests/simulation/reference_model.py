"""An independent plain-Python implementation of plant A's base equations for scipy ``solve_ivp``.

Written from docs/reference-plant.md directly (not from compliance.model.assembly) so the
cross-check compares two implementations: ISO 6358 flow (seed 000 eqs. 1-2), the tandem
chambers (decoded eqs. 4-5, isentropic at T_s), motion (decoded eq. 6) with LuGre friction
whose steady state is the sheet's map, PID + dead-zone compensation (eq. 3) at 1 ms ZOH.
Between controller samples the plant is integrated by ``solve_ivp`` (Radau, tight tolerances).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

L = 0.160
A_CAP = math.pi * 0.125**2 / 4
A_ROD = A_CAP - math.pi * 0.032**2 / 4
A_T = A_CAP + A_ROD
V0 = 98.17e-5
M = 30.0
PS, PATM, TS, R, GAMMA, RHO0, T0 = 8.0e5, 1.013e5, 293.15, 287.0, 1.4, 1.204, 293.15
C, B = 2.33e-8, 0.528
ZMD, ZME, USAT = 0.61, 0.69, 4.0
FS, FC, VS, BV = 420.0, 300.0, 0.005, 650.0
SIG0, SIG1 = 1e6, 3.873e3
KP, KI, TSAMP, LC = 280.0, 0.2, 1e-3, 0.4
FCUT = 50.0
KSTOP, CSTOP = 1e8, 5e4


def w(a):
    if a <= B:
        return 1.0
    if a >= 1.0:
        return 0.0
    a_lin = 0.999  # same regularisation as the documented model (near a = 1 the ellipse is vertical)
    if a > a_lin:
        r = (a_lin - B) / (1 - B)
        return math.sqrt(1 - r * r) * (1 - a) / (1 - a_lin)
    r = (a - B) / (1 - B)
    return math.sqrt(1 - r * r)


def qm(opening, p1, p2):
    """ISO 6358 mass flow from p1 to p2 (signed)."""
    if opening <= 0:
        return 0.0
    if p1 >= p2:
        return opening * C * p1 * RHO0 * w(p2 / p1)
    return -opening * C * p2 * RHO0 * w(p1 / p2)


def opening(u):
    if u >= 0:
        return min(max((u - ZMD) / (USAT - ZMD), 0.0), 1.0)
    return -min(max((-u - ZME) / (USAT - ZME), 0.0), 1.0)


def rhs(t, y, u, load):
    x, v, pa, pb, z = y
    op = opening(u)
    if op >= 0:
        qa = qm(op, PS, pa)
        qb = -qm(op, pb, PATM)
    else:
        qa = -qm(-op, pa, PATM)
        qb = qm(-op, PS, pb)
    va = 2 * V0 + A_T * x
    vb = 2 * V0 + A_T * (L - x)
    dpa = GAMMA / va * (R * TS * qa - pa * A_T * v)
    dpb = GAMMA / vb * (R * TS * qb + pb * A_T * v)
    g = FC + (FS - FC) * math.exp(-abs(v) / VS)
    dz = v - SIG0 * abs(v) * z / g
    ff = 2 * (SIG0 * z + SIG1 * dz + BV * v)
    fstop = 0.0
    if x < 0:
        fstop = max(-KSTOP * x - CSTOP * v, 0.0)
    elif x > L:
        fstop = min(-KSTOP * (x - L) - CSTOP * v, 0.0)
    acc = ((pa - pb) * A_T - ff - load + fstop) / M
    return [v, acc, dpa, dpb, dz]


def compensate(ud):
    if ud >= LC:
        return ud + ZMD
    if ud <= -LC:
        return ud - ZME
    if ud >= 0:
        return (ZMD + LC) / LC * ud
    return (ZME + LC) / LC * ud


def run(x0, load, kd, reference, duration, rtol=1e-9, atol=None):
    """Closed-loop run; ``reference(t)`` gives the set-point [m]. Returns (t, x) at the samples."""
    at = A_T
    pa = 0.5 * (PS + PATM) + 0.5 * load / at
    pb = 0.5 * (PS + PATM) - 0.5 * load / at
    y = np.array([x0, 0.0, pa, pb, 0.0])
    if atol is None:
        atol = np.array([1e-10, 1e-9, 1e-3, 1e-3, 1e-12])
    n = int(round(duration / TSAMP))
    alpha = 1 - math.exp(-2 * math.pi * FCUT * TSAMP)
    xf = x0
    integ = 0.0
    ts = np.arange(n + 1) * TSAMP
    xs = np.empty(n + 1)
    for k in range(n + 1):
        xs[k] = y[0]
        if k == n:
            break
        xm = y[0]
        xn = xf + alpha * (xm - xf)
        rate = (xn - xf) / TSAMP
        xf = xn
        e = reference(ts[k]) - xm
        integ += e * TSAMP
        ud = KP * e + KI * integ - kd * rate
        u = max(min(compensate(ud), 10.0), -10.0)
        sol = solve_ivp(rhs, (ts[k], ts[k + 1]), y, method="Radau", rtol=rtol, atol=atol, args=(u, load))
        y = sol.y[:, -1]
    return ts, xs

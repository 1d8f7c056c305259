"""Controller design for plant B from the linearised plant: pole placement and observer gains.

The design model is the third-order model of the position x, velocity v and acceleration a
of one axis (seed 001, "status variables x, v, a"), obtained from the simulator's own
right-hand side ``compliance.model.assembly.plant_rhs``:

1. trim at rest (valve at its centre, pressures balancing the load, ``plant.initial_state``);
2. central-difference Jacobian of (x, v, p_A, p_B) and of the valve command, with the friction
   replaced by its linear viscous part (k_v2 of seed 001 eq. 8; a discontinuous map has no
   derivative at rest, and the observer-based compensation deals with the rest);
3. the 4-state model x/u has one uncontrollable integrator (the mean chamber pressure at a
   shut critical-centre valve); ``control.minreal`` cancels it, leaving
   x/u = n0 / (s^3 + d2 s^2 + d1 s + d0), whose phase-variable form is exactly the (x, v, a)
   state model of seed 001.

The derivative at the valve centre is the mean of the two one-sided slopes (filling A and
emptying B for U > 0, the reverse for U < 0; they differ because supply and exhaust pressure
differences differ).

Gains: ``control.place`` on (A3, B3) for the state feedback; the reduced-order observers of
seed 001 eqs. (10)-(11) get their scalar error poles with ``control.place`` on the
(A22^T, A12^T) pair (duality).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import control
import numpy as np

from compliance.model.config import PlantConfig
from compliance.errors import InputError
from compliance.model.vector_slots import N_AUX, N_STATES, P_AREA_CAP, P_AREA_ROD, P_BV, P_FC, P_FRM, P_FS, P_UCEN, P_VLIM, P_VS, S_PA, S_PB, S_V, S_X
from compliance.model.assembly import plant_rhs
from compliance.model.plant_vector import load_curve_arrays, parameter_vector
from compliance.model.rest_state import initial_state

_STATES = (S_X, S_V, S_PA, S_PB)
_STEPS = (1e-6, 1e-6, 10.0, 10.0)  # central-difference steps: m, m/s, Pa, Pa (well inside the linear range)
_DU = 1e-3  # V, command step of the Jacobian
_MINREAL_TOL = 1e-6  # relative pole/zero cancellation tolerance of control.minreal


@dataclass(frozen=True)
class AxisModel:
    """Linear model of one axis about rest, x/u = n0 / (s^3 + d2 s^2 + d1 s + d0).

    Attributes
    ----------
    n0 : float
        Input gain [m/(s^3*V)].
    d0, d1, d2 : float
        Denominator coefficients [1/s^3], [1/s^2], [1/s].
    mass : float
        Moving mass [kg].
    area_a, area_b : float
        Piston areas of chambers A and B [m^2].
    atmosphere : float
        [Pa]; the rod side's atmospheric force is -p_atm*(A1 - A2).
    viscous : float
        Linear friction slope kept in the model [N*s/m].
    a4, b4 : ndarray
        Full 4-state Jacobian model (x, v, p_A, p_B).
    x0 : float
        Trim position [m].
    """

    n0: float
    d0: float
    d1: float
    d2: float
    mass: float
    area_a: float
    area_b: float
    atmosphere: float
    viscous: float
    a4: np.ndarray
    b4: np.ndarray
    x0: float

    @property
    def a3(self) -> np.ndarray:
        """Phase-variable state matrix of (x, v, a)."""
        return np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [-self.d0, -self.d1, -self.d2]])

    @property
    def b3(self) -> np.ndarray:
        """Input matrix of (x, v, a) [per V]."""
        return np.array([[0.0], [0.0], [self.n0]])

    @property
    def velocity_gain(self) -> float:
        """Static gain from valve command to speed K_0 = n0/d1 [m/(s*V)]."""
        return self.n0 / self.d1

    @property
    def natural_frequency(self) -> float:
        """Pneumatic spring natural frequency sqrt(d1) [rad/s]."""
        return math.sqrt(self.d1)

    def statespace(self) -> control.StateSpace:
        """The (x, v, a) model as a python-control StateSpace (outputs x, v, a)."""
        return control.ss(self.a3, self.b3, np.eye(3), np.zeros((3, 1)))


def _linear_friction(P: np.ndarray, viscous: float) -> np.ndarray:
    """Copy of the parameter vector with friction replaced by a pure viscous term."""
    Q = P.copy()
    Q[P_FRM] = 1.0  # variable-viscous branch with F_S = F_C = 0 is b*v
    Q[P_FS] = 0.0
    Q[P_FC] = 0.0
    Q[P_VS] = 1.0
    Q[P_BV] = viscous
    Q[P_VLIM] = 1e-12
    return Q


def linear_viscous(cfg: PlantConfig) -> float:
    """Friction slope kept in the linear model [N*s/m]: k_v2 (eq. 8) or the viscous coefficient."""
    if cfg.options["friction.model"] == "piecewise_stribeck":
        return cfg.p("friction.high_speed_coefficient")
    return cfg.p("friction.viscous_coefficient")


def axis_model(cfg: PlantConfig, *, x0: float | None = None, load: float | None = None) -> AxisModel:
    """Linearise one axis of ``cfg`` at rest at ``x0`` (default mid-stroke).

    Parameters
    ----------
    cfg : PlantConfig
        A single-cylinder configuration (``cylinder.arrangement = "single"``).
    x0 : float, optional
        Trim position [m].
    load : float, optional
        Constant closing load [N] (gravity on a vertical axis).

    Returns
    -------
    AxisModel
    """
    if cfg.options["cylinder.arrangement"] != "single":
        raise InputError(f"{cfg.path or cfg.name}: the tracking controller needs cylinder.arrangement = 'single'")
    stroke = cfg.p("cylinder.stroke")
    x0 = 0.5 * stroke if x0 is None else float(x0)
    P = parameter_vector(cfg, load=load)
    viscous = linear_viscous(cfg)
    Q = _linear_friction(P, viscous)
    y0 = initial_state(cfg, P, x0)
    lx, ly = load_curve_arrays(cfg)
    u0 = P[P_UCEN]
    dy = np.zeros(N_STATES)
    aux = np.zeros(N_AUX)

    def rhs(y, u):
        plant_rhs(y, Q, u, lx, ly, dy, aux)
        return dy[list(_STATES)].copy()

    a4 = np.zeros((4, 4))
    for j, (i, h) in enumerate(zip(_STATES, _STEPS)):
        yp, ym = y0.copy(), y0.copy()
        yp[i] += h
        ym[i] -= h
        a4[:, j] = (rhs(yp, u0) - rhs(ym, u0)) / (2.0 * h)
    b4 = ((rhs(y0, u0 + _DU) - rhs(y0, u0 - _DU)) / (2.0 * _DU))[:, None]
    tf = control.ss2tf(control.ss(a4, b4, [[1.0, 0.0, 0.0, 0.0]], [[0.0]]))
    red = control.minreal(tf, tol=_MINREAL_TOL, verbose=False)
    num = np.atleast_1d(np.squeeze(red.num[0][0]))
    den = np.atleast_1d(np.squeeze(red.den[0][0]))
    if den.size != 4:
        raise InputError(f"{cfg.path or cfg.name}: linearised axis is not third order after cancellation (order {den.size - 1})")
    den = den / den[0]
    num = num / red.den[0][0][0]
    n0 = float(num[-1])
    if np.any(np.abs(num[:-1]) > 1e-6 * abs(n0)):
        raise InputError(f"{cfg.path or cfg.name}: linearised axis has zeros; the (x, v, a) model does not apply")
    if not n0 > 0:
        raise InputError(f"{cfg.path or cfg.name}: valve command does not move the axis at rest (n0 = {n0:g}); check the valve")
    return AxisModel(
        n0=n0, d0=float(den[3]), d1=float(den[2]), d2=float(den[1]), mass=cfg.p("cylinder.moving_mass"),
        area_a=float(P[P_AREA_CAP]), area_b=float(P[P_AREA_ROD]), atmosphere=cfg.p("air.atmospheric_pressure"), viscous=viscous,
        a4=a4, b4=b4, x0=x0,
    )


# ----------------------------------------------------------------------------------------------
def design_poles(bandwidth: float, damping: float) -> np.ndarray:
    """Closed-loop poles: -w and -w*(zeta +/- j*sqrt(1 - zeta^2)) [rad/s]."""
    if not bandwidth > 0:
        raise InputError(f"controller.closed_loop_bandwidth must be > 0 rad/s for the state feedback, got {bandwidth:g}")
    wd = bandwidth * math.sqrt(max(1.0 - damping * damping, 0.0))
    return np.array([-bandwidth, -damping * bandwidth + 1j * wd, -damping * bandwidth - 1j * wd])


def state_feedback_gains(model: AxisModel, bandwidth: float, damping: float) -> np.ndarray:
    """State-feedback gains K = [k_x, k_v, k_a] placing ``design_poles`` (``control.place``).

    Returns
    -------
    ndarray
        [V/m, V*s/m, V*s^2/m].
    """
    poles = design_poles(bandwidth, damping)
    if damping >= 1.0:  # repeated real poles: place() refuses multiplicity > rank(B); Ackermann does not
        return np.asarray(control.acker(model.a3, model.b3, poles), float).ravel()
    return np.asarray(control.place(model.a3, model.b3, poles), float).ravel()


@dataclass(frozen=True)
class ReducedObserver:
    """Reduced-order (Gopinath) observer of seed 001 eqs. (10)-(11) for one unmeasured state.

    Model x1' = A11 x1 + A12 x2 + B1 u, x2' = A21 x1 + A22 x2 + B2 u with x1 measured; the
    estimate is x2^ = w + L x1 with

        w' = (A22 - L A12) w + (B2 - L B1) u + [L (A22 - L A12) + (A21 - L A11)] x1.

    Attributes
    ----------
    gain : ndarray
        L (row, one entry per measured state).
    pole : float
        A22 - L A12, the error dynamics [1/s].
    input_gain : ndarray
        B2 - L B1 (row, one entry per input).
    state_gain : ndarray
        L (A22 - L A12) + (A21 - L A11) (row, one entry per measured state).
    """

    gain: np.ndarray
    pole: float
    input_gain: np.ndarray
    state_gain: np.ndarray


def reduced_observer(a11, a12, a21, a22, b1, b2, bandwidth: float) -> ReducedObserver:
    """Design a reduced-order observer with its error pole at -``bandwidth`` (``control.place`` on the dual)."""
    a11, a12, a21, b1, b2 = (np.atleast_2d(np.asarray(m, float)) for m in (a11, a12, a21, b1, b2))
    a22 = np.atleast_2d(np.asarray(a22, float))
    if not bandwidth > 0:
        raise InputError(f"observer bandwidth must be > 0 rad/s, got {bandwidth:g}")
    # duality: eig(A22 - L A12) = eig(A22^T - A12^T L^T); place the single pole
    lt = np.asarray(control.place(a22.T, a12.T, [-bandwidth]), float)
    L = lt.T  # (1, n_measured)
    pole = float((a22 - L @ a12)[0, 0])
    input_gain = (b2 - L @ b1).ravel()
    state_gain = (L * pole + (a21 - L @ a11)).ravel()
    return ReducedObserver(gain=L.ravel(), pole=pole, input_gain=input_gain, state_gain=state_gain)


def acceleration_observer(model: AxisModel, bandwidth: float) -> ReducedObserver:
    """Seed 001 eq. (10): x1 = (x, v) measured, x2 = a; input the valve command about its centre."""
    a3, b3 = model.a3, model.b3
    return reduced_observer(a3[:2, :2], a3[:2, 2:], a3[2:, :2], a3[2:, 2:], b3[:2, :], b3[2:, :], bandwidth)


def friction_observer(model: AxisModel, bandwidth: float) -> ReducedObserver:
    """Seed 001 eq. (11): x1 = v measured, x2 = F_f (constant between samples), input u_p.

    v' = (A1 u_p - F_f)/M with u_p = p_A - (A2/A1) p_B in gauge pressures (seed 001 eq. 9 with
    the rod side's atmospheric force), so A11 = 0, A12 = -1/M, B11 = A1/M, A21 = A22 = B12 = 0.
    The whole friction (viscous part included) is the estimated state.
    """
    m = model.mass
    return reduced_observer([[0.0]], [[-1.0 / m]], [[0.0]], [[0.0]], [[model.area_a / m]], [[0.0]], bandwidth)


def pid_gains(model: AxisModel, gain_margin: float = 3.0, integral_corner: float = 0.2) -> tuple[float, float, float]:
    """PID gains for the comparison loop: P gain for a given gain margin, integral corner below crossover.

    The type-1 plant n0/(s(s^2 + d2 s + d1)) under P control u = k_p e has the characteristic
    polynomial s^3 + d2 s^2 + d1 s + n0 k_p, stable for k_p < d2 d1 / n0 (Routh); k_p is that
    limit divided by ``gain_margin``. K_D = 0: derivative feedback through the valve only
    stiffens the pneumatic spring (the s-term), it adds no damping to the s^2-term, which is
    why seed 001 feeds back the acceleration. K_I = k_p w_c ``integral_corner``, with w_c the
    gain crossover of the P loop (``control.margin``), so the integral corner sits a factor
    1/``integral_corner`` below it.

    Returns
    -------
    tuple of float
        (K_P [V/m], K_I [V/(m*s)], K_D [V*s/m]).
    """
    kp_limit = model.d2 * model.d1 / model.n0
    kp = kp_limit / gain_margin
    loop = control.tf([model.n0 * kp], [1.0, model.d2, model.d1, model.d0])
    _, _, _, wc = control.margin(loop)
    return kp, kp * float(wc) * integral_corner, 0.0


def friction_compensation_gain(model: AxisModel, gains: np.ndarray) -> float:
    """Static force per volt K_F of the state-feedback loop [N/V]: u_f = F_f^ / K_F.

    seed 001: G_f(s) = -1/(K_0 G(s)) with G(0) = 1. With the acceleration fed back, an extra
    command u_f at rest settles at a = n0 u_f / (d2 + n0 k_a) (the fast acceleration loop),
    i.e. a piston force M n0 u_f / (d2 + n0 k_a); K_F is that static gain.
    """
    ka = float(gains[2])
    return model.mass * model.n0 / (model.d2 + model.n0 * ka)

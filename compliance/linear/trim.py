"""Operating points and numerical linearisation of the ONE plant right-hand side.

The trim and the Jacobians call ``compliance.model.assembly.plant_rhs`` itself (no second model):

- trim: the gate at rest at ``position`` under ``load``, the valve inside its dead zone
  (no flow), chamber pressures balancing the load with the sum convention of
  ``plant.initial_state`` (p_A + p_B = p_s + p_atm: each side half-way between supply and
  exhaust, the state the simulator also starts from);
- friction: only its viscous part b*v enters the linear model (static and Coulomb friction
  and the LuGre bristle states are outside it, see docs/linear.md);
- valve: the dead zone makes d(flow)/d(command) zero at null, so the input column is the
  compensated valve (dead-zone inverse + valve) as an effective gain: the slope of the flow
  per unit opening times d(opening)/d(u_d) = 1/(md*(u_sat - dz)) beyond lc.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from compliance.effects.base import Balance
from compliance.effects.catalogue import ALL_EFFECTS
from compliance.effects.structure import trim_balance, trim_null, trim_states
from compliance.model.config import PlantConfig
from compliance.errors import InputError
from compliance.model.vector_slots import (EFFECT_SLOTS, N_AUX, N_STATES, P_AREA_CAP, P_AREA_ROD, P_ARR, P_BV, P_DZN, P_DZP,
                                           P_FC, P_FRM, P_FS, P_GAMMA, P_KV2, P_PATM, P_PS, P_STROKE, P_TS, P_UCEN, P_USAT,
                                           P_V0, P_VD_STAGE, P_VLIM, S_PA, S_PB, S_V, S_X, S_Z1, S_Z2, SHADOWS, STATE_INDEX,
                                           STATE_NAMES)
from compliance.model.assembly import plant_rhs
from compliance.model.plant_vector import load_curve_arrays, parameter_vector
from compliance.model.rest_state import initial_state, load_force, pneumatic_forces

GAIN_CHOICES = ("mean", "opening", "closing")
REL_STEP = 1e-6  # central-difference step relative to each state's scale (truncation ~1e-12, rounding ~1e-10)
OPENING_PROBE = 1e-4  # relative valve opening used to measure the flow slope per unit opening [-]


@dataclass(frozen=True)
class TrimPoint:
    """A trimmed operating point of the plant.

    Attributes
    ----------
    position : float
        Gate servomotor position [m] (0 = closed).
    load : float, "curve" or None
        The load as asked for.
    load_force : float
        Closing force at this position [N] (> 0 closes).
    pressure_a, pressure_b : float
        Chamber pressures at rest [Pa abs].
    state : numpy.ndarray
        Full trim state (layout ``STATE_NAMES``).
    params : numpy.ndarray
        Parameter vector with the friction replaced by its viscous part (used for the Jacobian).
    valve_null : float
        Valve voltage at the trim [V] (centre minus any null offset).
    residual : float
        Largest |dy/dt| of the trim state relative to its scale per second [1/s] (0 = exact rest).
    """

    position: float
    load: float | str | None
    load_force: float
    pressure_a: float
    pressure_b: float
    state: np.ndarray
    params: np.ndarray
    valve_null: float
    residual: float

    def to_dict(self) -> dict:
        """JSON-serialisable summary (SI units)."""
        return {
            "position": self.position, "load": self.load if isinstance(self.load, str) or self.load is None else float(self.load),
            "load_force": self.load_force, "pressure_a": self.pressure_a, "pressure_b": self.pressure_b,
            "valve_null": self.valve_null, "trim_residual": self.residual,
        }


def load_force_at(cfg: PlantConfig, P: np.ndarray, position: float) -> float:
    """Closing force on the gate at ``position`` [N]: constant or load curve, plus load stiffness."""
    lx, ly = load_curve_arrays(cfg)
    return load_force(P, position, lx, ly)


def _where(cfg: PlantConfig) -> str:
    return cfg.path or cfg.name


def trim(cfg: PlantConfig, position: float, load: float | str | None = None, *, flow_control: bool | None = None) -> TrimPoint:
    """Trim the nonlinear plant at rest at ``position`` under ``load``.

    Parameters
    ----------
    cfg : PlantConfig
    position : float
        [m], 0 <= position <= stroke.
    load : float, "curve" or None
        Constant closing load [N], the configuration's load curve, or none.
    flow_control : bool or None
        Override whether the meter-out flow-control valves are installed.

    Raises
    ------
    InputError
        Position outside the stroke, or a load the actuator cannot hold at the supply pressure.
    """
    L = cfg.p("cylinder.stroke")
    if not (isinstance(position, (int, float)) and math.isfinite(position)) or not 0.0 <= position <= L:
        raise InputError(f"{_where(cfg)}: operating point {position*1e3:.1f} mm is outside the stroke 0..{L*1e3:.0f} mm"
                         if isinstance(position, (int, float)) else f"{_where(cfg)}: operating point must be a position in metres")
    if load is not None and not isinstance(load, str) and not math.isfinite(float(load)):
        raise InputError(f"{_where(cfg)}: load must be a finite force in N, got {load!r}")
    P = parameter_vector(cfg, load=load, flow_control=flow_control)
    # a linear valve gain commutes with the valve's lag: filtering the command (spool stage) or the
    # opening it asks for (opening stage) is the same linear model, so both linearise as the spool
    P[P_VD_STAGE] = 0.0
    balance = Balance(position=position, tandem=bool(P[P_ARR] == 0.0), load=lambda x: load_force_at(cfg, P, x),
                      pressures=lambda f: _rest_pressures(P, f), piston_force=lambda pa, pb: pneumatic_forces(P, pa, pb)[0])
    shared = trim_balance(P, balance)  # an effect that shares the load between two bodies (a compliant linkage)
    if shared is None:
        f = load_force_at(cfg, P, position)
        (pa, pb, cap_closing, cap_opening), states = _rest_pressures(P, f), {}
    else:
        f, (pa, pb, cap_closing, cap_opening), states = shared
    ps, patm = P[P_PS], P[P_PATM]
    if not (patm <= pa <= ps and patm <= pb <= ps):
        raise InputError(
            f"{_where(cfg)}: load {f/1e3:.2f} kN at {position*1e3:.1f} mm cannot be held at the supply pressure "
            f"{ps/1e5:.2f} bar abs: the actuator holds at most {cap_closing/1e3:.2f} kN closing and {cap_opening/1e3:.2f} kN opening "
            f"((p_s - p_atm) x area)"
        )
    y = initial_state(cfg, P, position, (pa, pb))
    for index, value in states.items():
        y[index] = value
    null = trim_null(P, P[P_UCEN])  # the effects' shift of the valve's null (valve_offset)
    trim_states(P, y, null)  # the effects' states at the trim (a spool at the null)
    Pl = viscous_parameters(P)
    dy = rhs(Pl, y, null, cfg)
    scale = state_scales(Pl)
    return TrimPoint(float(position), load, f, float(pa), float(pb), y, Pl, float(null), float(np.max(np.abs(dy) / scale)))


def _rest_pressures(P: np.ndarray, f: float):
    """(p_A, p_B, largest closing load [N], largest opening load [N]) at rest under closing force ``f``."""
    ps, patm = P[P_PS], P[P_PATM]
    ac, ar = P[P_AREA_CAP], P[P_AREA_ROD]
    if P[P_ARR] == 0.0:
        pa = 0.5 * (ps + patm) + 0.5 * f / (ac + ar)  # tandem: (p_A - p_B)(A_cap + A_rod) = F, reference-plant.md
        pb = 0.5 * (ps + patm) - 0.5 * f / (ac + ar)
        return pa, pb, (ps - patm) * (ac + ar), (ps - patm) * (ac + ar)
    pa = (f + patm * (ac - ar) + (ps + patm) * ar) / (ac + ar)  # seed 001 eq. (9) with p_A + p_B = p_s + p_atm
    return pa, ps + patm - pa, (ps - patm) * ac, (ps - patm) * ar


def viscous_parameters(P: np.ndarray) -> np.ndarray:
    """Parameter vector whose friction is only the viscous term b*v (variable-viscous model, F_S = F_C = 0).

    With F_S = F_C = 0 and no limit speed, seed 000 eq. (7) reduces to F = b*v; the stick band,
    the Stribeck dip and the LuGre bristles (Canudas de Wit 1995) are switched off, and so are the
    effects' friction-level terms (``friction_level`` hook: factors on the static and Coulomb
    levels, gone with them). For the piecewise Stribeck model of seed 001 eq. (8) the viscous part is k_v2*v.
    """
    Pl = P.copy()
    if Pl[P_FRM] == 2.0:
        Pl[P_BV] = Pl[P_KV2]  # seed 001 eq. (8): the viscous slope above v_d
    Pl[P_FRM] = 1.0
    Pl[P_FS] = 0.0
    Pl[P_FC] = 0.0
    Pl[P_VLIM] = 0.0
    for eff in ALL_EFFECTS:
        if "friction_level" in eff.terms:
            Pl[EFFECT_SLOTS[eff.name][0]] = 0.0
    return Pl


_CACHE: dict = {}


def rhs(P: np.ndarray, y: np.ndarray, u: float, cfg: PlantConfig) -> np.ndarray:
    """dy/dt of ``plant_rhs`` (a fresh array)."""
    key = id(cfg)
    if key not in _CACHE or _CACHE[key][0] is not cfg:
        _CACHE.clear()
        _CACHE[key] = (cfg, load_curve_arrays(cfg))
    lx, ly = _CACHE[key][1]
    dy = np.zeros(N_STATES)
    plant_rhs(np.ascontiguousarray(y, dtype=float), P, float(u), lx, ly, dy, np.zeros(N_AUX))
    return dy


def state_scales(P: np.ndarray) -> np.ndarray:
    """Typical magnitude of each state (used for step sizes and for balancing); an effect's states by their
    declared ``State.scale``."""
    scales = {"stroke": P[P_STROKE], "speed": 0.1,  # m/s, the order of the full-stroke speeds
              "pressure": P[P_PS], "temperature": P[P_TS], "command": max(P[P_USAT], 1.0)}
    s = np.ones(N_STATES)
    s[S_X] = scales["stroke"]
    s[S_V] = scales["speed"]
    s[[S_PA, S_PB]] = scales["pressure"]
    s[[S_Z1, S_Z2]] = 1e-5
    for eff in ALL_EFFECTS:
        for st in eff.states:
            s[st.index] = st.scale(P, scales) if callable(st.scale) else scales[st.scale]
    return s


def _command_state(P: np.ndarray) -> tuple[int, list[int]] | None:
    """(index of the state carrying the valve command to the ports, its effect's state indices) of an
    effect switched on that declares one (``Effect.command_state``: a spool), or None."""
    for eff in ALL_EFFECTS:
        if eff.command_state and P[EFFECT_SLOTS[eff.name][0]]:
            return STATE_INDEX[eff.command_state], [st.index for st in eff.states]
    return None


def kept_states(P: np.ndarray) -> list[int]:
    """Indices of the states of the linear model: x, v, p_A, p_B plus the declared states of
    switched-on effects (``Effect.states``), in state-vector order."""
    keep = [S_X, S_V, S_PA, S_PB]
    for eff in ALL_EFFECTS:
        if P[EFFECT_SLOTS[eff.name][0]]:
            keep += [s.index for s in eff.states]
    return sorted(keep)


def state_jacobian(op: TrimPoint, cfg: PlantConfig, keep: list[int]) -> np.ndarray:
    """d(dy/dt)/dy over the kept states at the trim (central differences, scaled steps).

    Steps that would cross an end of the stroke are taken one-sided, so the end-stop spring
    never enters the Jacobian at 0 % or 100 % stroke.
    """
    P, y0, u = op.params, op.state, op.valve_null
    L = P[P_STROKE]
    scale = state_scales(P)
    J = np.zeros((len(keep), len(keep)))
    for j, s in enumerate(keep):
        h = REL_STEP * scale[s]
        lo, hi = -h, h
        if s == S_X or SHADOWS.get(s) == S_X:  # a position: never across an end of the stroke
            if y0[s] - h < 0.0:
                lo = 0.0 - y0[s]
            if y0[s] + h > L:
                hi = L - y0[s]
        yp = y0.copy()
        ym = y0.copy()
        yp[s] += hi
        ym[s] += lo
        for copy, of in SHADOWS.items():  # a state that does not move on its own follows its original
            if of == s and copy not in keep:
                yp[copy], ym[copy] = yp[s], ym[s]
        J[:, j] = ((rhs(P, yp, u, cfg) - rhs(P, ym, u, cfg)) / (hi - lo))[keep]
    return J


def valve_gain(cfg: PlantConfig, direction: str) -> float:
    """d(opening)/d(u_d) of the compensated valve beyond the smoothing width lc [1/V].

    Seed 000 eq. (3): u_c = u_d/md + zmd for u_d >= lc, and the opening is linear from the dead
    zone to 1 at u_sat (reference-plant.md), so d(opening)/du_d = 1/(md*(u_sat - zmd)); likewise
    with me, zme for the closing direction. Without compensation (lc = 0 and no inverse) the
    slope beyond the dead zone, 1/(u_sat - dz), is used.
    """
    p = cfg.params
    side = "positive" if direction == "opening" else "negative"
    span = p["valve.saturation_voltage"] - p[f"valve.dead_zone_{side}"]
    md = p[f"controller.compensation_slope_{side}"]
    return 1.0 / (md * span)


def flow_columns(op: TrimPoint, cfg: PlantConfig, keep: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """Change of dy/dt per unit relative opening, opening (P->A, B->T) and closing (P->B, A->T) [per 1].

    Measured through ``plant_rhs`` by opening the valve just past each dead-zone edge by
    ``OPENING_PROBE``. Flows are proportional to the opening (seed 000 eq. 1), so this is the
    slope at null; with a meter-out throttle in series it is the small-opening slope.
    """
    P, y0, null = op.params, op.state, op.valve_null
    carrier = _command_state(P)

    def at(u):
        if carrier is None:
            return rhs(P, y0, u, cfg)
        y = y0.copy()
        y[carrier[0]] = u  # the spool carries the command to the ports
        d = rhs(P, y, null, cfg)
        d[carrier[1]] = 0.0  # the spool's own rows are not a flow effect
        return d

    cols = []
    for sgn, dz in ((1.0, P[P_DZP]), (-1.0, P[P_DZN])):
        # from the dead-zone edge: a valve that leaks near null (valve_null_flow) already passes flow there,
        # which is not the opening's slope; an ideal valve passes none at the edge nor at null
        edge = null + sgn * dz
        u = edge + sgn * OPENING_PROBE * (P[P_USAT] - dz)  # path_opening = (u - dz)/(u_sat - dz)
        cols.append(sgn * (at(u) - at(edge))[keep] / OPENING_PROBE)
    return cols[0], cols[1]


def input_column(op: TrimPoint, cfg: PlantConfig, keep: list[int], gain: str = "mean") -> tuple[np.ndarray, np.ndarray, dict]:
    """Effective input column per volt of u_d and, with spool dynamics, the spool's flow column.

    Returns
    -------
    tuple
        (B [per V], flow column that replaces the spool-position column of A or None, info dict).
    """
    if gain not in GAIN_CHOICES:
        raise InputError(f"linear gain '{gain}' is not one of {', '.join(GAIN_CHOICES)}")
    g_open, g_close = flow_columns(op, cfg, keep)
    k_open, k_close = valve_gain(cfg, "opening"), valve_gain(cfg, "closing")
    b_open, b_close = g_open * k_open, g_close * k_close
    b = {"mean": 0.5 * (b_open + b_close), "opening": b_open, "closing": b_close}[gain]
    info = {"gain": gain, "opening_per_volt": {"opening": k_open, "closing": k_close}}
    P = op.params
    if _command_state(P) is None:
        return b, None, info
    # spool on: u_d drives the spool (unity static gain), the spool drives the flows with b
    h = 1e-6 * max(P[P_USAT], 1.0)
    Bu = (rhs(P, op.state, op.valve_null + h, cfg) - rhs(P, op.state, op.valve_null - h, cfg))[keep] / (2 * h)
    return Bu, b, info


def linearise_plant(op: TrimPoint, cfg: PlantConfig, gain: str = "mean"):
    """(A, B, C, state names, info) of u_d [V] -> position [m] at the trim ``op``."""
    keep = kept_states(op.params)
    A = state_jacobian(op, cfg, keep)
    B, spool_col, info = input_column(op, cfg, keep, gain)
    if spool_col is not None:
        carrier, own = _command_state(op.params)
        j = keep.index(carrier)
        rows = [i for i, s in enumerate(keep) if s not in own]
        A[rows, j] = spool_col[rows]
    C = np.zeros((1, len(keep)))
    C[0, keep.index(S_X)] = 1.0
    names = [STATE_NAMES[s] for s in keep]
    info["state_scales"] = state_scales(op.params)[keep].tolist()
    return A, B.reshape(-1, 1), C, names, info


def minimal_realisation(A, B, C, scales, tol=1e-9):
    """(A, B, C) of a minimal realisation of a SISO system, by orthogonal projection on the controllable, then observable Krylov subspaces.

    python-control's ``minreal`` needs slycot (not installed); this is the textbook Kalman
    decomposition done with Arnoldi on the state-scaled system, enough for the <= 12 states here.
    At a valve null the common level of the two chamber pressures is such a mode: no flow
    changes it from x, and it moves no force (tandem) -- it is unobservable from the position.
    """
    T = np.diag(scales)
    A = np.linalg.solve(T, A @ T)
    B = np.linalg.solve(T, B)
    C = C @ T
    for transpose in (False, True):
        a, b = (A.T, C.T) if transpose else (A, B)
        V = _krylov(a, b[:, 0], tol)
        A, B, C = V.T @ A @ V, V.T @ B, C @ V
    return A, B, C


def _krylov(A, b, tol):
    n = A.shape[0]
    norm = max(np.linalg.norm(A, 2), 1e-300)
    basis = []
    v = b.astype(float)
    for _ in range(n):
        for _pass in range(2):  # twice is enough (Kahan-Parlett)
            for q in basis:
                v = v - (q @ v) * q
        nv = np.linalg.norm(v)
        ref = norm * (np.linalg.norm(basis[-1]) if basis else np.linalg.norm(b))
        if nv <= tol * max(ref, 1e-300) or (not basis and nv == 0.0):
            break
        q = v / nv
        basis.append(q)
        v = A @ q
    return np.array(basis).T if basis else np.zeros((n, 0))


def pneumatic_stiffness(op: TrimPoint) -> float:
    """Pneumatic spring k = gamma*(A_A^2 p_A/V_A + A_B^2 p_B/V_B) at the trim [N/m] (isentropic, Merritt 1967).

    Tandem: A_A = A_B = A_cap + A_rod (reference-plant.md); single: A_A = A_cap, A_B = A_rod.
    """
    P = op.params
    ac, ar, L, x = P[P_AREA_CAP], P[P_AREA_ROD], P[P_STROKE], op.position
    if P[P_ARR] == 0.0:
        aa = ab = ac + ar
        va, vb = 2 * P[P_V0] + aa * x, 2 * P[P_V0] + aa * (L - x)
    else:
        aa, ab = ac, ar
        va, vb = P[P_V0] + ac * x, P[P_V0] + ar * (L - x)
    return P[P_GAMMA] * (aa * aa * op.pressure_a / va + ab * ab * op.pressure_b / vb)

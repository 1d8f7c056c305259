"""The pieces every compiled loop shares: one RK4 step, one sample recorder, delay histories.

The plant is integrated with classical RK4 at the pinned step ``simulation.step`` (several
steps per controller sample). Valve and sensor delays use histories sampled on that grid,
averaged over each step so results move continuously with the delay (the diagnosis fits need it).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
import pandas as pd
from numba import njit

from compliance.model.assembly import plant_rhs
from compliance.effects.heat_transfer import P_HT_ON, S_TA, S_TB
from compliance.effects.sensor_lag import P_SL_TAU, P_SL_TD
from compliance.effects.supply_droop import P_SD_ON, S_PSUP
from compliance.model.vector_slots import A_FRIC, A_LOAD, A_OPEN, A_QA, A_QB, N_AUX, N_STATES, P_PS, P_TS
from compliance.model.vector_slots import S_PA, S_PB, S_V, S_X

OUTPUT_COLUMNS = (
    "time", "position", "reference", "valve_command", "pressure_a", "pressure_b", "supply_pressure",
    "position_true", "velocity", "load_force", "friction_force", "flow_a", "flow_b", "opening",
    "temperature_a", "temperature_b", "command_demand",
)
(O_T, O_XM, O_REF, O_U, O_PA, O_PB, O_PS, O_X, O_V, O_LOAD, O_FRIC, O_QA, O_QB, O_OPEN, O_TA, O_TB, O_UD) = range(len(OUTPUT_COLUMNS))
N_OUT = len(OUTPUT_COLUMNS)


def output_buffer(n_rows: int, n_columns: int = N_OUT) -> np.ndarray:
    """An (n_rows, n_columns) output array for a compiled loop, stored column by column.

    The loops write one row per controller sample; stored by column, a pandas DataFrame takes the
    columns without copying them (row by row, a 30 s run would need a 4 MB transposing copy costing
    half the loop's own time), and every caller passes this one layout, so each loop is compiled
    once. Not initialised: a loop that returns success has written every cell.
    """
    return np.empty((n_columns, n_rows)).T


@lru_cache(maxsize=None)
def _column_index(columns: tuple) -> pd.Index:
    return pd.Index(list(columns))


def output_frame(out: np.ndarray, columns: tuple = OUTPUT_COLUMNS) -> pd.DataFrame:
    """The DataFrame of an ``output_buffer`` filled by a loop, on the same memory (no copy).

    The column index is built once per column set (building it from the names is ~30 us a run).
    """
    return pd.DataFrame(out, columns=_column_index(columns).copy(), copy=False)


@njit(cache=True, error_model="numpy", inline="always")
def zoh_average(hist, ts, t_a, t_b):
    """Average over [t_a, t_b] of the zero-order-hold signal hist[k] on [k*ts, (k+1)*ts)."""
    n = hist.shape[0]
    ka = int(math.floor(t_a / ts))
    kb = int(math.floor(t_b / ts))
    if ka < 0:
        ka = -1
    if kb < 0:
        kb = -1
    va = hist[0] if ka < 0 else hist[min(ka, n - 1)]
    if ka == kb or t_b <= t_a:
        return va
    vb = hist[0] if kb < 0 else hist[min(kb, n - 1)]
    t_sw = kb * ts
    return (va * (t_sw - t_a) + vb * (t_b - t_sw)) / (t_b - t_a)


@njit(cache=True, error_model="numpy", inline="always")
def interp_uniform(hist, h, t):
    """Linear interpolation of a signal sampled every ``h`` from t = 0 (held before 0)."""
    if t <= 0.0:
        return hist[0]
    f = t / h
    i = int(math.floor(f))
    n = hist.shape[0]
    if i >= n - 1:
        return hist[n - 1]
    w = f - i
    return hist[i] * (1.0 - w) + hist[i + 1] * w


@njit(cache=True, error_model="numpy", inline="always")
def record_sample(out, k, ts, xm, ref_k, u, u_d, y, aux, P):
    """Write the canonical columns of controller sample ``k`` (shared by every compiled loop)."""
    out[k, O_T] = k * ts
    out[k, O_XM] = xm
    out[k, O_REF] = ref_k
    out[k, O_U] = u
    out[k, O_PA] = y[S_PA]
    out[k, O_PB] = y[S_PB]
    out[k, O_PS] = y[S_PSUP] if P[P_SD_ON] != 0.0 else P[P_PS]
    out[k, O_X] = y[S_X]
    out[k, O_V] = y[S_V]
    out[k, O_LOAD] = aux[A_LOAD]
    out[k, O_FRIC] = aux[A_FRIC]
    out[k, O_QA] = aux[A_QA]
    out[k, O_QB] = aux[A_QB]
    out[k, O_OPEN] = aux[A_OPEN]
    out[k, O_TA] = y[S_TA] if P[P_HT_ON] != 0.0 else P[P_TS]
    out[k, O_TB] = y[S_TB] if P[P_HT_ON] != 0.0 else P[P_TS]
    out[k, O_UD] = u_d


@njit(cache=True, error_model="numpy", inline="always")
def rk4_step(y, P, u, lx, ly, h, k1, k2, k3, k4, tmp, aux, k1_ready=False):
    """One classical RK4 step in place; ``k1_ready`` reuses a slope already evaluated at (y, u)."""
    n = y.shape[0]
    if not k1_ready:
        plant_rhs(y, P, u, lx, ly, k1, aux)
    for i in range(n):
        tmp[i] = y[i] + 0.5 * h * k1[i]
    plant_rhs(tmp, P, u, lx, ly, k2, aux)
    for i in range(n):
        tmp[i] = y[i] + 0.5 * h * k2[i]
    plant_rhs(tmp, P, u, lx, ly, k3, aux)
    for i in range(n):
        tmp[i] = y[i] + h * k3[i]
    plant_rhs(tmp, P, u, lx, ly, k4, aux)
    for i in range(n):
        y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])



@njit(cache=True, error_model="numpy", inline="always")
def rk4_workspace():
    """Scratch arrays of :func:`rk4_step`: k1, k2, k3, k4, tmp (N_STATES each) and aux (N_AUX)."""
    return (np.zeros(N_STATES), np.zeros(N_STATES), np.zeros(N_STATES), np.zeros(N_STATES), np.zeros(N_STATES),
            np.zeros(N_AUX))


@njit(cache=True, error_model="numpy", inline="always")
def measured_position(x, noise, quantum):
    """What the position sensor reports [m]: ``x`` plus additive noise, rounded to ``quantum`` (0 = none)."""
    xm = x + noise
    if quantum > 0.0:
        xm = quantum * math.floor(xm / quantum + 0.5)
    return xm


@njit(cache=True, error_model="numpy", inline="always")
def non_physical(y):
    """Whether the state has left physics: non-finite, a non-positive chamber pressure or |v| > 100 m/s."""
    if not (math.isfinite(y[S_X]) and math.isfinite(y[S_PA]) and math.isfinite(y[S_PB])):
        return True
    return y[S_PA] <= 0.0 or y[S_PB] <= 0.0 or abs(y[S_V]) > 100.0


@njit(cache=True, error_model="numpy", inline="always")
def sensor_lag_coefficients(P, h):
    """(decay, ramp) of the sensor's first-order lag over one step ``h`` [s], exact for a ramp input.

    decay = exp(-h/tau) (0 = no lag); ramp = 1 - tau/h (1 - decay), 1 in the tau -> 0 limit where
    the sensor reads the (delayed) position itself.
    """
    tau = P[P_SL_TAU]
    if tau <= 0.0:
        return 0.0, 1.0
    decay = math.exp(-h / tau)
    return decay, 1.0 - tau / h * (1.0 - decay)


@njit(cache=True, error_model="numpy", inline="always")
def sensor_lag_start(P, x, v, on):
    """(reading, delayed position [m], speed [m/s]) of the lagged sensor at the start of a run.

    Where a steady motion at the initial speed ``v`` leaves it (at rest: on the true position ``x``):
    a ramp trails a delay t_d and a first-order lag tau by v (t_d + tau). ``on``: the sensor lag is on.
    """
    if not on:
        return x, x, 0.0
    xd = x - v * P[P_SL_TD]
    return xd - v * P[P_SL_TAU], xd, v


@njit(cache=True, error_model="numpy", inline="always")
def sensor_lag_advance(x_hist, step_index, x, h, delay, x_sensor, xd_prev, decay, ramp, v0):
    """Store the true position of step ``step_index`` and advance the delayed, lagged sensor one step.

    Before t = 0 the piston is taken to have moved steadily at ``v0`` [m/s] (0: at rest), the
    history a run started mid-motion (a re-synchronised replay segment) had.

    Returns
    -------
    tuple
        (sensor reading [m], delayed position at this step [m]).
    """
    x_hist[step_index] = x
    t = step_index * h - delay
    xd = interp_uniform(x_hist, h, t) if t >= 0.0 else x_hist[0] + v0 * t
    # first-order lag integrated exactly for an input linear over the step
    return decay * x_sensor + (1.0 - decay) * xd_prev + (xd - xd_prev) * ramp, xd

"""Valve flow from charging or discharging a known fixed volume (seed 000 sec. 3, seed 001 figs. 2-4).

A rigid, adiabatic volume V filled through the valve obeys (seed 001 eq. (3) with dV/dt = 0)

    dp/dt = gamma R T_s q / V      ->      q = V / (gamma R T_s) * dp/dt          (charging)

with T_s the supply temperature of the inflowing air. Emptying it through the valve to the
exhaust, the remaining gas expands isentropically, T = T_0 (p/p_0)^((gamma-1)/gamma), and the
energy balance of the rigid volume gives q_out = -V / (gamma R T) * dp/dt (Beater,
"Pneumatic Drives", Springer 2007, ch. 3). dp/dt comes from a Savitzky-Golay derivative
(cubic, fitted on the actual sample times; ``derivative.py``), never from raw differences:
seed 001 reports that differencing the measured pressure gives "large error in q_m".
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.integrate import solve_ivp

from compliance.errors import InputError
from compliance.recordings.column_map import CANONICAL_UNITS
from compliance.units import ATMOSPHERE_PA
from compliance.characterise.derivative import noise_std, odd_window, savgol_weights, smoothed_derivative
from compliance.characterise.flow_law import GAMMA, LAWS, R_AIR, T0, FlowFit, rank_flow_laws

PRESSURE_COLUMNS = tuple(name for name, unit in CANONICAL_UNITS.items() if unit == "Pa")

DERIVATIVE_ORDER = 3  # cubic Savitzky-Golay: same centre-point noise as quadratic, smaller bias


def mass_flow_from_pressure(time, pressure, volume, temperature, *, mode="charge", window=11, gamma=GAMMA, r_gas=R_AIR):
    """Mass flow into (charge) or out of (discharge) a rigid volume from its pressure trace.

    Parameters
    ----------
    time : array_like
        Sample times [s].
    pressure : array_like
        Absolute pressure in the volume [Pa].
    volume : float
        Volume including the pipe up to the valve [m^3].
    temperature : float
        Supply temperature (charge) or initial gas temperature (discharge) [K].
    mode : {"charge", "discharge"}
    window : int
        Odd Savitzky-Golay window [samples].
    gamma, r_gas : float
        Heat capacity ratio [-], gas constant [J/(kg*K)].

    Returns
    -------
    (p_smooth, mass_flow, gas_temperature)
        Smoothed pressure [Pa], mass flow [kg/s] (positive in the direction of ``mode``) and
        the temperature of the gas that flows [K].
    """
    p, dpdt = smoothed_derivative(time, pressure, window, DERIVATIVE_ORDER)
    factor, t_gas = _flow_factor(p, volume, temperature, mode, gamma, r_gas)
    return p, factor * dpdt, t_gas


def _flow_factor(p, volume, temperature, mode, gamma=GAMMA, r_gas=R_AIR):
    """q = factor * dp/dt for the rigid volume; returns (factor [kg/Pa], gas temperature [K])."""
    if mode == "charge":
        t_gas = np.full_like(p, float(temperature))
        return volume / (gamma * r_gas * t_gas), t_gas  # seed 001 eq. (3) with dV/dt = 0
    if mode == "discharge":
        t_gas = temperature * (np.clip(p, 1.0, None) / p[0]) ** ((gamma - 1.0) / gamma)  # isentropic expansion
        return -volume / (gamma * r_gas * t_gas), t_gas  # energy balance of the rigid volume (Beater 2007)
    raise InputError(f"mode must be 'charge' or 'discharge', got {mode!r}")


@dataclass(frozen=True)
class ValveCharacterisation:
    """Result of ``characterise_valve``: ranked fits plus the samples they were fitted on."""

    source: str
    mode: str
    volume: float
    temperature: float
    window: int
    derivative: str
    fits: tuple[FlowFit, ...]
    pressure_noise: float
    time: np.ndarray
    p_up: np.ndarray
    p_down: np.ndarray
    t_up: np.ndarray
    mass_flow: np.ndarray

    @property
    def best(self) -> FlowFit:
        """The fit with the lowest AIC."""
        return self.fits[0]

    def to_dict(self) -> dict:
        """JSON-ready summary (SI units)."""
        return {
            "source": self.source,
            "mode": self.mode,
            "volume_m3": self.volume,
            "temperature_K": self.temperature,
            "derivative": self.derivative,
            "window_samples": self.window,
            "samples_used": int(self.time.size),
            "pressure_noise_Pa": self.pressure_noise,
            "time_range_s": [float(self.time[0]), float(self.time[-1])],
            "ranking": [
                {"law": f.law, "equation": f.equation, "params": f.params, "stderr": f.stderr, "units": f.units,
                 "rms_kg_per_s": f.rms, "aic": f.aic, "n": f.n, "n_eff": f.n_eff}
                for f in self.fits
            ],
        }


def characterise_valve(
    frame: pd.DataFrame,
    volume: float,
    *,
    supply_pressure: float | None = None,
    exhaust_pressure: float = ATMOSPHERE_PA,
    temperature: float = T0,
    pressure_column: str = "pressure_a",
    mode: str = "auto",
    window: int | None = None,
    laws=tuple(LAWS),
    max_ratio: float = 0.97,
    source: str = "recording",
) -> ValveCharacterisation:
    """Fit and rank flow laws on a charging / discharging recording of a fixed volume.

    Parameters
    ----------
    frame : pandas.DataFrame
        Canonical recording with ``time`` [s] and ``pressure_column`` [Pa abs]; a
        ``supply_pressure`` column [Pa abs] is used for charging when present.
    volume : float
        The fixed volume [m^3].
    supply_pressure : float, optional
        Supply pressure [Pa abs] if the recording has no ``supply_pressure`` column.
    exhaust_pressure : float
        Exhaust pressure for discharging [Pa abs].
    temperature : float
        Supply temperature [K].
    mode : {"auto", "charge", "discharge"}
        ``auto``: charge if the pressure rises over the record.
    window : int, optional
        Savitzky-Golay window [samples]; default 4 % of the samples of the transient (the
        5-95 % part of the pressure change), at least 7.
    laws : iterable of str
        Laws to fit (default all).
    max_ratio : float
        Samples whose downstream/upstream ratio exceeds this are not fitted: close to
        equilibrium q -> 0 and the relative error of dp/dt grows without bound.
    source : str
        Name for messages and reports.

    Returns
    -------
    ValveCharacterisation
    """
    if not volume > 0:
        raise InputError(f"{source}: volume must be > 0 m^3, got {volume}")
    if pressure_column not in PRESSURE_COLUMNS:
        raise InputError(f"{source}: --pressure-column '{pressure_column}' is not a pressure; expected one of "
                         f"{', '.join(PRESSURE_COLUMNS)}")
    for col in ("time", pressure_column):
        if col not in frame.columns:
            raise InputError(f"{source}: needs a '{col}' column; has {', '.join(frame.columns)}")
    t = frame["time"].to_numpy(dtype=float)
    p_raw = frame[pressure_column].to_numpy(dtype=float)
    mode, window = _mode_and_window(t, p_raw, mode, window, pressure_column, source)
    idx, w_value, w_deriv = savgol_weights(t, window, DERIVATIVE_ORDER)
    p = np.sum(w_value * p_raw[idx], axis=1)
    factor, t_gas = _flow_factor(p, volume, temperature, mode)
    q = factor * np.sum(w_deriv * p_raw[idx], axis=1)
    sigma_p = noise_std(t, p_raw, window, DERIVATIVE_ORDER, weights=(idx, w_value, w_deriv))
    p_up, p_down, other = _ends(frame, p, mode, supply_pressure, exhaust_pressure, source)
    t_up = t_gas
    _check_upstream(p_up, p_down, sigma_p, mode, f"'{pressure_column}'", other, source)
    used = _fitted_span(q, p_down / p_up, window, max_ratio, source, mode=mode, t=t)
    flow_noise = (idx[used], factor[used, None] * w_deriv[used], sigma_p)
    fits = rank_flow_laws(
        p_up[used], p_down[used], t_up[used], q[used], laws, correlation_length=float(window), flow_noise=flow_noise
    )
    return ValveCharacterisation(
        source=source, mode=mode, volume=float(volume), temperature=float(temperature), window=int(window),
        derivative=f"Savitzky-Golay, cubic, {window} samples, on the sample times",
        fits=tuple(fits), pressure_noise=sigma_p, time=t[used], p_up=p_up[used], p_down=p_down[used], t_up=t_up[used], mass_flow=q[used],
    )


def _mode_and_window(t, p_raw, mode: str, window: int | None, pressure_column: str, source: str) -> tuple[str, int]:
    """Charge or discharge (``auto``: whether the pressure rises) and the derivative window [samples]."""
    k = max(3, t.size // 50)
    rise = np.median(p_raw[-k:]) - np.median(p_raw[:k])  # [Pa] from the first to the last 2 % of samples
    if mode == "auto":
        mode = "charge" if rise > 0 else "discharge"
    change = np.abs(p_raw - p_raw[0])
    total = np.max(change)
    if not total > 0:
        raise InputError(f"{source}: pressure '{pressure_column}' never changes; not a charging/discharging record")
    if (mode == "charge" and rise < -0.5 * total) or (mode == "discharge" and rise > 0.5 * total):
        raise InputError(
            f"{source}: --mode {mode}, but '{pressure_column}' {'falls' if rise < 0 else 'rises'} by "
            f"{abs(rise) * 1e-5:.3g} bar over the record; give --mode {'discharge' if rise < 0 else 'charge'} (or auto)"
        )
    if window is None:
        transient = np.count_nonzero((change > 0.05 * total) & (change < 0.95 * total))
        window = odd_window(max(7, 0.04 * transient), DERIVATIVE_ORDER)
    if mode not in ("charge", "discharge"):
        raise InputError(f"{source}: mode must be 'auto', 'charge' or 'discharge', got {mode!r}")
    if window % 2 == 0 or window <= DERIVATIVE_ORDER + 1 or t.size < 2 * window:
        raise InputError(
            f"{source}: derivative window {window} samples must be odd, > {DERIVATIVE_ORDER + 1} and at most half "
            f"the recording ({t.size} samples)"
        )
    return mode, window


def _ends(frame, p, mode: str, supply_pressure, exhaust_pressure, source: str):
    """Upstream and downstream pressure [Pa abs] of the valve, and where the other one came from."""
    if mode == "discharge":
        return p, np.full_like(p, float(exhaust_pressure)), "--exhaust-pressure"
    if "supply_pressure" in frame.columns:
        return frame["supply_pressure"].to_numpy(dtype=float), p, "the supply_pressure column"
    if supply_pressure is not None:
        return np.full_like(p, float(supply_pressure)), p, "--supply-pressure"
    raise InputError(f"{source}: charging needs the supply pressure: a 'supply_pressure' column or --supply-pressure")


def _check_upstream(p_up, p_down, sigma_p: float, mode: str, chamber: str, other: str, source: str) -> None:
    """Refuse an upstream pressure below the downstream one: gas flows from high to low pressure.

    A tolerance of 2 % of the highest upstream pressure plus 5 noise standard deviations (our
    choice) lets a chamber settle onto its supply or exhaust without a false refusal.
    """
    excess = p_down - p_up
    worst = int(np.argmax(excess))
    if excess[worst] <= 0.02 * np.max(p_up) + 5.0 * sigma_p:
        return
    bar = 1e-5
    if mode == "charge":
        what = (f"{chamber} reaches {p_down[worst] * bar:.3g} bar abs, above the supply {p_up[worst] * bar:.3g} bar abs "
                f"({other}): a volume cannot charge above its supply; check that pressure's value and unit")
    else:
        what = (f"the exhaust {p_down[worst] * bar:.3g} bar abs ({other}) is above {chamber} "
                f"({p_up[worst] * bar:.3g} bar abs): a volume cannot discharge below its exhaust; check that "
                f"pressure's value and unit, or --mode")
    raise InputError(f"{source}: {what}")


def _fitted_span(q, ratio, window: int, max_ratio: float, source: str, *, mode: str = "charge", t=None) -> slice:
    """Samples to fit: from the valve opening (past the smeared edge) to the pressure ratio ``max_ratio``."""
    n = q.size
    half = window // 2
    opening = int(np.argmax(q >= 0.5 * np.max(q)))
    start = opening + half  # valve open, past the smeared opening edge
    if start >= n - half - 10:
        at = f" (t = {t[opening]:.4g} s)" if t is not None else ""
        raise InputError(
            f"{source}: the derivative window of {window} samples leaves no samples after the valve opening{at}: "
            f"{n - opening} samples follow it; give a smaller --window (or none for the default)"
        )
    beyond = np.flatnonzero(ratio[start:] > max_ratio)
    stop = start + int(beyond[0]) if beyond.size else n - half
    used = slice(start, min(stop, n - half))
    if used.stop - used.start < 10:
        raise InputError(
            f"{source}: only {max(used.stop - used.start, 0)} samples between the valve opening and the pressure ratio "
            f"{max_ratio} (ratio {ratio[start]:.3g} at the opening); record faster or a larger volume"
        )
    return used


def synthetic_charging(
    law: str,
    params: dict,
    *,
    volume: float,
    supply_pressure: float,
    initial_pressure: float,
    duration: float,
    sample_time: float,
    temperature: float = T0,
    mode: str = "charge",
    exhaust_pressure: float = ATMOSPHERE_PA,
    delay: float = 0.0,
    noise_std: float = 0.0,
    seed: int = 0,
) -> pd.DataFrame:
    """Pressure in a fixed volume charged (or discharged) through a known flow law.

    Integrates the equations of ``mass_flow_from_pressure`` (solve_ivp, RK45, rtol 1e-10)
    and adds seeded Gaussian noise of ``noise_std`` [Pa] to the chamber pressure.

    Parameters
    ----------
    law : str
        Name in ``flow_law.LAWS``; ``params`` gives its parameters in SI.
    volume : float [m^3]
    supply_pressure, initial_pressure, exhaust_pressure : float [Pa abs]
    duration, sample_time, delay : float [s]
        ``delay``: the valve opens at t = delay.
    temperature : float [K]
    mode : {"charge", "discharge"}
    noise_std : float [Pa]
    seed : int

    Returns
    -------
    pandas.DataFrame
        ``time`` [s], ``pressure_a`` [Pa abs], ``supply_pressure`` [Pa abs].
    """
    fit = FlowFit(law, "", dict(params), {}, {}, 0.0, 0.0, 0, 0.0)

    def rhs(t, y):
        p = y[0]
        if t < delay:
            return [0.0]
        if mode == "charge":
            q = fit.predict(supply_pressure, p, temperature)[0]
            return [GAMMA * R_AIR * temperature * q / volume]  # seed 001 eq. (3), dV/dt = 0
        t_gas = temperature * (p / initial_pressure) ** ((GAMMA - 1.0) / GAMMA)
        q = fit.predict(p, exhaust_pressure, t_gas)[0]
        return [-GAMMA * R_AIR * t_gas * q / volume]

    target = supply_pressure if mode == "charge" else exhaust_pressure

    def settled(t, y):  # laws with dq/dp -> inf at dp = 0 reach equilibrium in finite time
        return abs(target - y[0]) - 1.0

    settled.terminal = True
    n = int(round(duration / sample_time)) + 1
    t = np.arange(n) * sample_time
    sol = solve_ivp(rhs, (0.0, t[-1]), [initial_pressure], t_eval=t, rtol=1e-10, atol=1e-3, max_step=sample_time * 10,
                    events=settled)
    p = np.full(n, target, dtype=float)  # within 1 Pa of equilibrium once settled
    p[: sol.y.shape[1]] = sol.y[0]
    if noise_std > 0:
        p = p + np.random.default_rng(seed).normal(0.0, noise_std, n)
    return pd.DataFrame({"time": t, "pressure_a": p, "supply_pressure": np.full(n, float(supply_pressure))})

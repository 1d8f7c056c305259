"""Seed 001's flow-law experiment by simulation: charge a fixed volume, fit each law to the flow trend.

The paper charged a fixed volume through the proportional valve, differentiated the pressure
to get a "flow rate trend curve" (q = V/(gamma R T_s) dp/dt, its eq. (3) with dV/dt = 0) and
found that neither Sanville's law (eq. 5) nor Bobrow's (eq. 6) fits it, while its own power law
(eq. 7, lambda = 0.25) does (figs. 2-4, lost). Here the "measured" charging record comes from
a more detailed valve than any of the three laws: ISO 6358 with b = 0.3 plus a laminar term
(``flow_rating.detailed_valve_flow``), integrated to 1e-10 relative accuracy, with seeded
pressure-sensor noise. The flow trend and the fits are those of ``compliance.characterise``
(Savitzky-Golay derivative, least squares per law), so the claim is checked with the same code
a user runs on a bench record.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.integrate import solve_ivp

from compliance.characterise.charging import characterise_valve
from compliance.characterise import flow_rating as FR

LAWS_COMPARED = ("sanville", "bobrow", "power-0.25", "iso6358")
VOLUME = 2.0e-3  # m^3, the fixed volume charged (assumed: a 2 L reservoir)
NOISE = 200.0  # Pa, pressure-sensor noise std (assumed: 0.02 % of a 10 bar sensor)


def charging_record(supply, atmosphere, *, volume=VOLUME, temperature=FR.NORMAL_TEMPERATURE, nominal_flow=700.0,
                    duration=1.5, sample_time=1e-3, noise_std=NOISE, seed=1, delay=0.05, b=FR.DETAILED_B,
                    laminar_share=FR.DETAILED_LAMINAR_SHARE) -> pd.DataFrame:
    """Pressure of a fixed volume charged through the detailed valve from ``atmosphere`` [Pa abs].

    Parameters
    ----------
    supply, atmosphere : float
        Absolute pressures [Pa].
    volume : float [m^3]
    temperature : float
        Supply temperature [K].
    nominal_flow : float
        Valve rating [NL/min].
    duration, sample_time, delay : float [s]
        ``delay``: the valve opens fully at t = delay.
    noise_std : float
        Gaussian pressure noise [Pa], seeded by ``seed``.
    b, laminar_share : float
        Critical ratio and laminar share of the detailed valve (``flow_rating.detailed_valve_flow``).

    Returns
    -------
    pandas.DataFrame
        ``time`` [s], ``pressure_a`` [Pa abs], ``supply_pressure`` [Pa abs].
    """
    q_r = FR.rated_mass_flow(nominal_flow)
    p1, p2 = FR.rating_point(atmosphere)
    k = 1.4 * 287.0 * temperature / volume

    def rhs(t, y):
        if t < delay:
            return [0.0]
        return [k * float(FR.detailed_valve_flow(supply, min(y[0], supply), temperature, q_r, p1, p2, b, laminar_share))]  # seed 001 eq. (3), V const

    n = int(round(duration / sample_time)) + 1
    t = np.arange(n) * sample_time
    sol = solve_ivp(rhs, (0.0, t[-1]), [atmosphere], t_eval=t, rtol=1e-10, atol=1e-4, max_step=sample_time)
    p = sol.y[0] + np.random.default_rng(seed).normal(0.0, noise_std, n)
    return pd.DataFrame({"time": t, "pressure_a": p, "supply_pressure": np.full(n, float(supply))})


@dataclass(frozen=True)
class FlowClaim:
    """Outcome of the flow-law experiment.

    Attributes
    ----------
    fits : dict
        Law -> ``characterise.flow_law.FlowFit``.
    relative_rms : dict
        Law -> residual RMS / peak trend flow [-].
    pressure, trend : ndarray
        Chamber pressure [Pa] and flow trend [kg/s] of the fitted samples.
    true_flow : ndarray
        The detailed valve's flow at those pressures [kg/s] (noise-free truth).
    supply : float [Pa]
    """

    fits: dict
    relative_rms: dict
    pressure: np.ndarray
    trend: np.ndarray
    true_flow: np.ndarray
    supply: float

    def predict(self, law: str, pressure) -> np.ndarray:
        """Flow of a fitted law charging from the supply at ``pressure`` [kg/s]."""
        p = np.asarray(pressure, float)
        return self.fits[law].predict(np.full_like(p, self.supply), p, np.full_like(p, FR.NORMAL_TEMPERATURE))


def flow_claim(supply, atmosphere, **record_options) -> FlowClaim:
    """Run the experiment: record, differentiate, fit Sanville, Bobrow, the power law and ISO 6358."""
    rec = charging_record(supply, atmosphere, **record_options)
    vol = record_options.get("volume", VOLUME)
    ch = characterise_valve(rec, vol, supply_pressure=supply, temperature=FR.NORMAL_TEMPERATURE, mode="charge",
                            laws=LAWS_COMPARED, source="simulated charging (detailed valve)")
    fits = {f.law: f for f in ch.fits}
    peak = float(np.max(ch.mass_flow))
    q_r = FR.rated_mass_flow(700.0)
    p1, p2 = FR.rating_point(atmosphere)
    truth = FR.detailed_valve_flow(supply, ch.p_down, FR.NORMAL_TEMPERATURE, q_r, p1, p2,
                                   record_options.get("b", FR.DETAILED_B),
                                   record_options.get("laminar_share", FR.DETAILED_LAMINAR_SHARE))
    return FlowClaim(fits, {k: f.rms / peak for k, f in fits.items()}, ch.p_down, ch.mass_flow, truth, float(supply))


def sensitivity(supply, atmosphere, b_values=(0.2, 0.3, 0.4), laminar_shares=(0.0, 0.05, 0.1)) -> list[dict]:
    """Relative RMS of each law for other detailed valves (noise-free records): where the claim holds."""
    rows = []
    for b in b_values:
        for share in laminar_shares:
            c = flow_claim(supply, atmosphere, noise_std=0.0, b=b, laminar_share=share)
            rows.append({"b": b, "laminar_share": share, **{k: float(v) for k, v in c.relative_rms.items()}})
    return rows

"""What a replay of one recording is made of, prepared once: its grid, signals, start, noise, segments and conditions.

``validation.replay.prepare_replay`` builds a ``ReplaySetup`` from a recording; ``run_replay``
simulates it on any plant configuration.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.signal import savgol_filter

from compliance.model.config import PlantConfig
from compliance.validation.recorded_noise import position_quantum
from compliance.validation.replay_conditions import CONTROLLER_KEYS, INITIAL_WINDOW, supply_source

STATE_WINDOW = 41  # samples; Savitzky-Golay window for the states read from the recording
VELOCITY_WINDOW = 81  # samples; cubic S-G derivative: 20 um noise at 1 kHz -> ~0.25 mm/s velocity noise


@dataclass
class ReplaySetup:
    """Everything a replay needs besides the plant configuration.

    Attributes
    ----------
    time : ndarray
        Controller-sample grid [s] from 0 (the recording's own time base).
    reference : ndarray
        Set-point per sample [m].
    command : ndarray
        Recorded valve command [V] (the input where the command drives).
    closed_loop : bool
        The model's controller runs (from the start to ``command_from``).
    command_from : int
        First sample the recorded valve command drives the plant (``time.size``: none; 0: all).
    load : float or "curve"
        Constant closing load [N] or the configuration's load curve.
    initial_position : float
        [m].
    initial_pressures : tuple or None
        Measured (p_A, p_B) at the start [Pa abs], else the at-rest trim.
    noise : ndarray
        Position noise injected into the model's measurement [m] (zero where the command drives).
    recorded : dict
        Canonical signal -> recorded array (measured signals only).
    resets : ndarray
        Sample indices where a segment starts (first is 0).
    states : dict
        Smoothed recorded states used at the resets: position, velocity, pressure_a,
        pressure_b, supply_pressure (those measured), integral (the controller's integral of
        the recorded error [m*s]).
    overrides : dict
        Base-parameter overrides from the recording's sidecar.
    flow_control : bool or None
        Flow-control valves installed in the test (None: as configured).
    conditions : dict
        The test conditions the replay assumed, each with where it came from.
    notes : list of str
    source : str
    logged : ndarray or None
        Controller periods at which the logger wrote a sample (None: every period); residuals,
        noise floors and the injected noise use these samples only.
    logger : LoggerModel or None
        What the logger did to the signals (``validation.logger_model``), applied to every replay.
    resolution : dict
        Measured signal -> quantisation step [SI]: declared (``metadata["channels"]``) or the
        lattice of the logged samples (0 when none).
    noise_replay : bool
        The recording's own noise is fed to the model's controller.
    full_scale : dict
        Pressure signal -> (low, high) [Pa abs] where its transducer saturated (either None when it
        did not; ``full_scale``).
    """

    time: np.ndarray
    reference: np.ndarray
    command: np.ndarray
    closed_loop: bool
    load: float | str
    initial_position: float
    initial_pressures: tuple[float, float] | None
    noise: np.ndarray
    recorded: dict
    resets: np.ndarray
    states: dict
    overrides: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)
    source: str = "<recording>"
    logged: np.ndarray | None = None
    logger: object = None
    resolution: dict = field(default_factory=dict)
    command_from: int = -1
    flow_control: bool | None = None
    conditions: dict = field(default_factory=dict)
    noise_replay: bool = False
    full_scale: dict = field(default_factory=dict)

    def __post_init__(self):
        if self.command_from < 0:
            self.command_from = self.time.size if self.closed_loop else 0

    @property
    def n_samples(self) -> int:
        """Number of controller periods simulated."""
        return self.time.size - 1

    @property
    def samples(self) -> np.ndarray:
        """Indices of the controller grid that carry a logged sample."""
        return np.arange(self.time.size) if self.logged is None else self.logged

    def config(self, cfg: PlantConfig) -> PlantConfig:
        """``cfg`` with the recording's controller and supply overrides applied (what ``run_replay`` takes)."""
        return cfg.replace(params=self.overrides) if self.overrides else cfg


def _smooth(values: np.ndarray, deriv: int = 0, dt: float = 1.0, window: int = STATE_WINDOW) -> np.ndarray:
    w = min(window, values.size - (1 - values.size % 2))
    if w < 5:
        return np.gradient(values, dt) if deriv else values.copy()
    return savgol_filter(values, w, 3, deriv=deriv, delta=dt)


def _smooth(values: np.ndarray, deriv: int = 0, dt: float = 1.0, window: int = STATE_WINDOW) -> np.ndarray:
    w = min(window, values.size - (1 - values.size % 2))
    if w < 5:
        return np.gradient(values, dt) if deriv else values.copy()
    return savgol_filter(values, w, 3, deriv=deriv, delta=dt)


def recorded_states(rec: dict, reference: np.ndarray | None, ts: float) -> dict:
    """The smoothed recorded states a segment restarts from (``ReplaySetup.states``).

    Position and its velocity (cubic Savitzky-Golay, ``STATE_WINDOW`` and ``VELOCITY_WINDOW``
    samples), the measured pressures, and with a set-point the controller's integral of the
    recorded error at each sample [m*s].
    """
    states = {"position": _smooth(rec["position"]), "velocity": _smooth(rec["position"], 1, ts, VELOCITY_WINDOW)}
    for s in ("pressure_a", "pressure_b", "supply_pressure"):
        if s in rec:
            states[s] = _smooth(rec[s])
    if reference is not None:
        err = reference - rec["position"]
        states["integral"] = np.concatenate([[0.0], np.cumsum(err)[:-1] * ts])  # the controller's I state at each sample
    return states


SATURATED_RUN = 10  # consecutive samples at exactly a channel's extreme: a transducer at its full scale


def full_scale(rec: dict, logged: np.ndarray | None) -> dict:
    """Pressure signal -> (low, high) where its transducer saturated, each None when it did not [Pa abs].

    A transducer past its range reads its full scale, exactly, sample after sample (a 0-10 bar
    transmitter under a closing stroke's compressed chamber reads 10 bar while the chamber holds
    more); a live reading with noise never repeats one value ``SATURATED_RUN`` times at its extreme.
    The replay does not restart a segment from such a reading and clips its own signal where the
    transducer did.
    """
    out = {}
    for s in ("pressure_a", "pressure_b", "supply_pressure"):
        if s not in rec:
            continue
        v = rec[s] if logged is None else rec[s][logged]
        levels = []
        for extreme in (float(np.min(v)), float(np.max(v))):
            at = np.concatenate(([0], (v == extreme).astype(np.int8), [0]))
            edges = np.flatnonzero(np.diff(at))
            longest = int(np.max(edges[1::2] - edges[::2])) if edges.size else 0
            levels.append(extreme if longest >= SATURATED_RUN and np.ptp(v) > 0 else None)
        if levels != [None, None]:
            out[s] = tuple(levels)
    return out


def clip_to_full_scale(values: np.ndarray, levels: tuple) -> np.ndarray:
    """``values`` as the saturating transducer reads them (``full_scale``)."""
    lo, hi = levels
    return np.clip(values, -np.inf if lo is None else lo, np.inf if hi is None else hi)


def resolutions(rec: dict, logged: np.ndarray | None, meta: dict) -> dict:
    """Signal -> quantisation step [SI]: the channel's declared resolution, else the logged samples' lattice."""
    channels = meta.get("channels") or {}
    out = {}
    for s, v in rec.items():
        declared = (channels.get(s) or {}).get("resolution")
        out[s] = float(declared) if declared else position_quantum(v if logged is None else v[logged])
    return out


def replay_conditions(run_cfg: PlantConfig, meta: dict, init: dict, start: float, load, load_source: str, overrides: dict, fc,
                      switch) -> dict:
    """The test conditions the replay assumed, each with where it came from."""
    window = f"{INITIAL_WINDOW*1e3:.0f} ms"
    return {
        "initial_position": init["initial_position"],
        "initial_position_source": f"median of the recorded position over the first {window} (the operating point: the load's "
                                   "anchor)",
        "start_position": start,
        "start_position_source": "the recorded position smoothed at the first sample (cubic Savitzky-Golay, as every "
                                 "re-synchronised segment starts): the replay starts at rest there",
        "initial_pressures": init["initial_pressures"],
        "initial_pressures_source": (f"medians of the recorded pressures over the first {window}" if init["initial_pressures"]
                                     else "at rest balancing the load, mean (p_s + p_atm)/2 (pressures not recorded)"),
        "load_force": load,
        "load_source": load_source,
        "supply_pressure": run_cfg.p("air.supply_pressure"),
        "supply_pressure_source": supply_source(meta, overrides),
        "flow_control": run_cfg.flow_control_installed if fc is None else fc,
        "flow_control_source": "configuration" if fc is None else "sidecar test.flow_control",
        "command_from": switch,
        "controller": {k: run_cfg.p(d) for k, d in CONTROLLER_KEYS.items()},
    }


__all__ = ["ReplaySetup", "SATURATED_RUN", "STATE_WINDOW", "VELOCITY_WINDOW", "clip_to_full_scale", "full_scale", "recorded_states",
           "replay_conditions", "resolutions"]

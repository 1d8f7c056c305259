"""What the logger does to a signal between the plant and the file: anti-alias filter, delay, calibration.

A replay simulates what the plant and the controller did; the recording is what the logger made
of it. To compare like with like, the simulated channels go through the same instruments the
recording declares (``compliance.recordings.instruments``):

- a first-order anti-alias filter H(s) = 1 / (1 + s / (2 pi f_c)) (an RC stage; its phase lag at
  low frequency is a delay of 1 / (2 pi f_c): 2 ms at 80 Hz), discretised with the bilinear
  (Tustin) map at the controller period, started at rest on the first value;
- a delay: the channel reads what the plant did ``delay`` seconds earlier (a second acquisition
  module, a transmitter's own processing), linear interpolation between controller samples;
- a calibration: recorded = gain * true + offset, on gauge pressure for a pressure channel
  (transducers measure against the atmosphere).

The same object carries the instrumentation candidates of the diagnosis (a fitted channel-group
delay or pressure gain) as extra delays and gains on top of the declared ones.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.signal import lfilter

from compliance.units.quantities import ATMOSPHERE_PA

FILTERED = ("position", "valve_command", "pressure_a", "pressure_b", "supply_pressure")  # the set-point is the input
PRESSURES = ("pressure_a", "pressure_b", "supply_pressure")


@dataclass(frozen=True)
class LoggerModel:
    """Per-channel instruments applied to simulated signals (every mapping: channel -> SI value).

    Attributes
    ----------
    cutoff : dict
        First-order anti-alias cutoff [Hz].
    delay : dict
        Channel delay [s] (>= 0 later than the controller clock; < 0 earlier).
    gain : dict
        Relative calibration gain [-] (1 = exact).
    offset : dict
        Calibration offset [channel SI unit].
    """

    cutoff: dict = field(default_factory=dict)
    delay: dict = field(default_factory=dict)
    gain: dict = field(default_factory=dict)
    offset: dict = field(default_factory=dict)

    @property
    def active(self) -> bool:
        """True when the model changes any signal."""
        return bool(self.cutoff or any(self.delay.values()) or any(g != 1.0 for g in self.gain.values())
                    or any(self.offset.values()))

    def with_extra(self, delay: dict | None = None, gain: dict | None = None, offset: dict | None = None) -> "LoggerModel":
        """The model with further delays added and gains / offsets composed (instrumentation candidates)."""
        d = dict(self.delay)
        for k, v in (delay or {}).items():
            d[k] = d.get(k, 0.0) + float(v)
        g = dict(self.gain)
        for k, v in (gain or {}).items():
            g[k] = g.get(k, 1.0) * float(v)
        o = dict(self.offset)
        for k, v in (offset or {}).items():
            o[k] = o.get(k, 0.0) + float(v)
        return replace(self, delay=d, gain=g, offset=o)

    def noise_share(self, name: str, ts: float) -> float:
        """Share of white noise (standard deviation, sampled every ``ts`` [s]) the channel's filter passes [-].

        A transducer's noise as the controller read it is the logged noise divided by this: a
        first-order filter at 80 Hz passes half of 1 kHz white noise (sum of its squared impulse response).
        """
        fc = self.cutoff.get(name)
        if not fc:
            return 1.0
        impulse = np.zeros(int(20.0 / (2.0 * math.pi * fc * ts)) + 50)  # 20 time constants
        impulse[0] = 1.0
        h = lfilter(*_coefficients(fc, ts), impulse)
        return float(np.sqrt(np.sum(h * h)))

    def true_states(self, states: dict, ts: float) -> dict:
        """Recorded states as the plant had them: calibration undone, delays taken back [SI arrays every ``ts``].

        The replay reads measured states at its re-synchronisations; a channel logged ``delay``
        late shows at t what the plant had at t - delay, and a gain error scales what it shows.
        ``velocity`` follows the position's delay. Filters are not undone (that would amplify noise).
        """
        out = dict(states)
        for name in FILTERED:
            if name not in out:
                continue
            x = np.asarray(out[name], dtype=float)
            g, o = self.gain.get(name, 1.0), self.offset.get(name, 0.0)
            if g != 1.0 or o:
                x = ATMOSPHERE_PA + (x - o - ATMOSPHERE_PA) / g if name in PRESSURES else (x - o) / g
            d = self.delay.get(name, 0.0)
            if d:
                t = np.arange(x.size) * ts
                x = np.interp(t + d, t, x)
                if name == "position" and "velocity" in out:
                    out["velocity"] = np.interp(t + d, t, np.asarray(out["velocity"], dtype=float))
            out[name] = x
        return out

    def apply(self, signals: dict, ts: float) -> dict:
        """Simulated signals as the logger records them (arrays on the controller grid of step ``ts`` [s]).

        Signals without instruments, and every key not in ``FILTERED``, are returned unchanged.
        """
        out = dict(signals)
        for name in FILTERED:
            if name not in out:
                continue
            x = np.asarray(out[name], dtype=float)
            fc = self.cutoff.get(name)
            if fc:
                x = first_order_filter(x, fc, ts)
            d = self.delay.get(name, 0.0)
            if d:
                t = np.arange(x.size) * ts
                x = np.interp(t - d, t, x)
            g, o = self.gain.get(name, 1.0), self.offset.get(name, 0.0)
            if g != 1.0 or o:
                x = (ATMOSPHERE_PA + g * (x - ATMOSPHERE_PA) if name in PRESSURES else g * x) + o
            out[name] = x
        return out


class LoggedPrefix:
    """The logger applied to a replay while it runs: logged values of the samples whose inputs are all final.

    ``LoggerModel.apply`` on the whole replay gives the same numbers bit for bit: the filter runs on, chunk
    after chunk, from the state it ended in (``lfilter``'s ``zi``/``zf``), a delayed sample interpolates
    between the same two simulated samples, and the calibration is the same arithmetic. A sample's logged
    value is final once the samples it reads are: its own and earlier ones (filter, delay >= 0), or up to
    ``lead`` samples later (a negative delay: the channel shows what the plant does later).

    Parameters
    ----------
    logger : LoggerModel
    ts : float
        Controller period [s].
    n : int
        Samples of the replay.
    """

    def __init__(self, logger: LoggerModel, ts: float, n: int):
        self.logger, self.ts = logger, ts
        self.t = np.arange(n) * ts
        ahead = max((-d for d in logger.delay.values()), default=0.0)
        self.lead = int(math.ceil(ahead / ts)) + 1 if ahead > 0.0 else 0
        self._filtered: dict = {}  # channel -> [samples filtered so far, filter state, how many, coefficients]

    def values(self, name: str, x: np.ndarray, final: int, idx: np.ndarray) -> np.ndarray:
        """Logged channel ``name`` at samples ``idx`` (each below ``final - lead``); ``x`` is the simulated
        channel, final up to sample ``final`` (exclusive)."""
        lg = self.logger
        fc = lg.cutoff.get(name)
        if fc:
            if name not in self._filtered:
                b, a = _coefficients(fc, self.ts)
                self._filtered[name] = [np.empty(self.t.size), np.array([x[0] * (1.0 - b[0])]), 0, (b, a)]
            buf, zi, done, (b, a) = self._filtered[name]
            if final > done:
                buf[done:final], zi = lfilter(b, a, x[done:final], zi=zi)
                self._filtered[name][1:3] = [zi, final]
            x = buf
        d = lg.delay.get(name, 0.0)
        v = np.interp(self.t[idx] - d, self.t[:final], x[:final]) if d else x[idx]
        g, o = lg.gain.get(name, 1.0), lg.offset.get(name, 0.0)
        if g != 1.0 or o:
            v = (ATMOSPHERE_PA + g * (v - ATMOSPHERE_PA) if name in PRESSURES else g * v) + o
        return v


def _coefficients(cutoff: float, ts: float) -> tuple[np.ndarray, np.ndarray]:
    wc = 2.0 / ts * math.tan(math.pi * cutoff * ts)  # prewarped: the discrete filter's -3 dB point is the cutoff
    k = 2.0 / ts
    return np.array([wc, wc]) / (k + wc), np.array([1.0, (wc - k) / (k + wc)])


def first_order_filter(x: np.ndarray, cutoff: float, ts: float) -> np.ndarray:
    """First-order low-pass at ``cutoff`` [Hz] of samples every ``ts`` [s] (Tustin, prewarped), at rest on x[0]."""
    if not x.size:
        return np.asarray(x, dtype=float)
    b, a = _coefficients(cutoff, ts)
    y, _ = lfilter(b, a, x, zi=np.array([x[0] * (1.0 - b[0])]))
    return y


def logger_model(metadata: dict | None) -> LoggerModel | None:
    """The instruments a recording's metadata declares (``instruments.instrument_facts``), or None.

    The logger's ``anti_alias_cutoff`` applies to every measured channel (``FILTERED``) that does
    not declare its own; channel ``delay``, ``gain`` and ``offset`` apply to that channel.
    """
    metadata = metadata or {}
    logger = metadata.get("logger") or {}
    channels = metadata.get("channels") or {}
    cutoff, delay, gain, offset = {}, {}, {}, {}
    for name in FILTERED:
        facts = channels.get(name) or {}
        fc = facts.get("anti_alias_cutoff", logger.get("anti_alias_cutoff"))
        if fc:
            cutoff[name] = float(fc)
        if facts.get("delay"):
            delay[name] = float(facts["delay"])
        if "gain" in facts:
            gain[name] = float(facts["gain"])
        if facts.get("offset"):
            offset[name] = float(facts["offset"])
    model = LoggerModel(cutoff, delay, gain, offset)
    return model if model.active else None

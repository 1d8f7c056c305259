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

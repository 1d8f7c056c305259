"""Where the nominal model misses: located windows and their operating regimes.

A thin adapter over ``compliance.validation.locate`` and ``compliance.validation.regimes`` (the same windows
``govcheck validate`` shows), applied to the diagnosis' re-synchronised nominal replay. It
returns the merged events (one per stretch of misfit, with the signals involved and the
dominant regimes), a sample mask of where they are, and the before/after agreement per event.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from compliance.model.config import PlantConfig
from compliance.validation.locate import LocateSettings, locate, merge_across_signals
from compliance.validation.regimes import compute_regimes
from compliance.validation.fit_metrics import per_unit_bases

REGIME_WORDS = {
    "holding_under_load": "while the servo holds its load",
    "at_rest": "while the position holds",
    "valve_dead_band": "with the valve in its dead band",
    "moving": "while the piston moves",
    "opening": "while opening",
    "closing": "while closing",
    "after_reversal": "after reversals",
    "valve_saturated": "with the valve fully open",
    "a_choked": "with choked flow to side A",
    "b_choked": "with choked flow to side B",
}


def _frame(time, signals: dict, names) -> pd.DataFrame:
    return pd.DataFrame({"time": time, **{s: signals[s] for s in names}})


def locate_mismatch(cfg: PlantConfig, setup, signals, nominal: dict):
    """Located events of the nominal replay.

    Parameters
    ----------
    cfg : PlantConfig
        Replay configuration.
    setup : validation.replay.ReplaySetup
    signals : sequence of str
        Compared signals.
    nominal : dict
        Nominal replay (signal -> array).

    Returns
    -------
    (list of dict, ndarray of bool, dict)
        Events (``start``, ``end``, ``duration`` [s], ``signals`` {signal: peak ratio},
        ``dominant`` regimes, ``i_start``, ``i_end``), the sample mask they cover, and the
        regime masks.
    """
    rec = _frame(setup.time, setup.recorded, signals)
    if setup.closed_loop and "reference" not in rec:
        rec["reference"] = setup.reference
    sim = _frame(setup.time, nominal, signals)
    load = setup.load
    regimes = compute_regimes(rec, cfg, load, cfg.p("air.supply_pressure"))
    bases = {k: v["value"] for k, v in per_unit_bases(cfg).items()}
    exclude = () if setup.closed_loop else ("valve_command",)
    settings = LocateSettings()
    windows, _, _ = locate(rec, sim, regimes, bases, settings, exclude=exclude, resolutions=setup.resolution)
    events = merge_across_signals(windows, regimes, settings.merge_gap)
    mask = np.zeros(setup.time.size, dtype=bool)
    for e in events:
        mask[e["i_start"]:e["i_end"] + 1] = True
    return events, mask, regimes.masks


def event_rms(events, recorded: dict, model: dict | None, floors: dict, signals) -> list[dict | None]:
    """Normalised residual RMS of each event and signal (None when there is no model)."""
    if model is None:
        return [None for _ in events]
    out = []
    for e in events:
        sl = slice(e["i_start"], e["i_end"] + 1)
        row = {}
        for s in signals:
            r = recorded[s][sl] - model[s][sl]
            row[s] = float(np.sqrt(np.mean(r * r)) / floors[s])
        out.append(row)
    return out


def mask_agreement(model, vec_nominal: np.ndarray, vec_candidate: np.ndarray, mask: np.ndarray) -> float:
    """Share of a candidate's chi-square reduction that falls inside the located events [0..1].

    ``model`` is the ``ResidualModel``; the vectors are its normalised residual vectors.
    """
    inside = mask[model.index]
    m = np.tile(inside, len(model.signals))
    d = vec_nominal ** 2 - vec_candidate ** 2
    total = float(np.sum(d))
    if total <= 0:
        return 0.0
    return float(min(max(np.sum(d[m]) / total, 0.0), 1.0))


def where_words(events, regime_masks=None) -> list[str]:
    """The dominant regimes of the events, in words, most frequent first."""
    counts: dict[str, float] = {}
    for e in events:
        for r in e.get("dominant", []):
            if r in REGIME_WORDS:
                counts[r] = counts.get(r, 0.0) + e.get("duration", 0.0)
    # the more specific regime first when both describe the same stretch
    order = sorted(counts, key=lambda r: -counts[r])
    if "holding_under_load" in order and "at_rest" in order:
        order.remove("at_rest")
    return [REGIME_WORDS[r] for r in order[:3]]

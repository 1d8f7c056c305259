"""A recording and its sidecar checked against the plant they claim, before any replay.

The reader checks what is impossible for any bench (plausibility.py); this module checks what
is impossible for *this* plant, and names the likely slip instead of letting the simulator
report "non-physical" later: a load the cylinder cannot hold or none given at all, positions
outside the stroke (millimetres logged without a unit), a proportional gain a thousand times
the plant's (V/mm written as V/m), a start position that the recording contradicts.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from compliance.errors import InputError
from compliance.model.force_limit import check_load_force
from compliance.recordings.metadata import sidecar_path
from compliance.recordings.plausibility import check_no_gaps, constant_hint, pressure_slip

__all__ = ["check_against_plant"]

START_WINDOW = 0.05  # [s] the recorded start position: median of the first 50 ms (as the replay takes it)
START_MISMATCH = 0.05  # fraction of the stroke: sidecar start vs recorded start beyond this contradicts
GAIN_MISMATCH = 30.0  # sidecar kp vs the plant's beyond this factor is a unit slip, not a retuning


def _number(table, key):
    v = table.get(key) if isinstance(table, dict) else None
    return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else None


def check_against_plant(cfg, frame: pd.DataFrame, meta: dict, recording) -> None:
    """Refuse a recording or sidecar value this plant cannot have produced (see the module docstring).

    Parameters
    ----------
    cfg : PlantConfig
        The plant the recording is replayed with.
    frame : pandas.DataFrame
        The canonical recording (SI).
    meta : dict
        Its metadata (sidecar, SI floats).
    recording : path-like
        The recording, for messages.

    Raises
    ------
    InputError
        Naming the file, the key or column, the value and the likely slip.
    """
    check_no_gaps(recording, frame["time"].to_numpy())
    side_file = sidecar_path(recording)
    # the file that declared the conditions: the sidecar, else the column map's [metadata] (never a file that is not there)
    side = (str(side_file) if side_file.is_file() else
            f"{meta['column_map']}: metadata" if meta.get("column_map") else f"{recording} (no sidecar)")
    cond = meta.get("conditions") if isinstance(meta.get("conditions"), dict) else {}
    if "load_force" not in cond:
        where = (side if side_file.is_file() or meta.get("column_map") else
                 f"{recording}: no sidecar ({side_file.name}, beside the recording, does not exist)")
        raise InputError(
            f"{where}: the test's load is not given ([conditions] load_force); the replay cannot guess it and a wrong "
            "load ends in a non-physical simulation: write load_force in N (> 0 closes; 0 for none; \"curve\" for the "
            f"plant's load curve){'' if side_file.is_file() else f' in a sidecar {side_file.name} next to the recording'}")
    check_load_force(cfg, _number(cond, "load_force"), f"{side}: conditions.load_force")
    stroke = cfg.p("cylinder.stroke")
    _check_positions(frame, stroke, recording)
    x0 = _number(cond, "initial_position")
    if x0 is not None and "position" in frame:
        t = frame["time"].to_numpy()
        start = float(np.median(frame["position"].to_numpy()[t <= t[0] + START_WINDOW]))
        if abs(x0 - start) > START_MISMATCH * stroke:
            # millimetres written as metres give a start beyond the stroke; a value inside it is a position in m
            unit = (" (it looks like mm written without a unit)"
                    if x0 > stroke and abs(x0 / 1e3 - start) < START_MISMATCH * stroke else "")
            unplugged = constant_hint(frame["position"].to_numpy(), "position")
            raise InputError(f"{side}: conditions.initial_position = {x0:.6g} m{unit} contradicts the recording, which starts "
                             f"at {start * 1e3:.2f} mm (median of the first {START_WINDOW * 1e3:.0f} ms){unplugged}; "
                             "correct the sidecar" + (" or the recording" if unplugged else ""))
    kp, plant_kp = _number(meta.get("controller"), "kp"), cfg.p("controller.kp")
    if kp is not None and kp > 0 and plant_kp > 0 and not 1 / GAIN_MISMATCH < kp / plant_kp < GAIN_MISMATCH:
        ratio = kp / plant_kp
        hint = (" - it looks like V/mm written as V/m" if 0.3e-3 < ratio < 3e-3 else
                " - it looks like V/m written as V/mm" if 0.3e3 < ratio < 3e3 else "")
        raise InputError(f"{side}: controller.kp = {kp:.6g} V/m is {ratio:.3g} x the plant's {plant_kp:.6g} V/m{hint}; "
                         "the sidecar's gains replace the plant's in the replay: give kp in V/m (or with its unit, \"0.28 V/mm\")")
    ps = _number(cond, "supply_pressure")
    if ps is not None:
        slip = pressure_slip(ps)
        if slip:
            raise InputError(f"{side}: conditions.supply_pressure = {ps:.6g} Pa abs{slip}; write the unit (\"8 bar abs\")")


def _check_positions(frame: pd.DataFrame, stroke: float, recording) -> None:
    for name in ("position", "reference"):
        if name not in frame:
            continue
        v = frame[name].to_numpy()
        margin = 0.25 * stroke  # sensor offsets and overtravel; beyond this the unit is wrong
        bad = np.flatnonzero((v < -margin) | (v > stroke + margin))
        if bad.size:
            med = float(np.median(v))
            hint = constant_hint(v, name) or (" - it looks like millimetres written without a unit"
                                              if med >= 1.0 and med / 1e3 < stroke + margin else "")
            raise InputError(f"{recording}: column '{name}' reaches {float(v[bad[0]]):.6g} m ({bad.size} samples outside "
                             f"the plant's stroke 0..{stroke * 1e3:.0f} mm){hint}; the canonical position is in m "
                             "(or give a column map with the unit)")

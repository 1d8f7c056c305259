"""COMTRADE (IEEE C37.111) recordings: a ``NAME.cfg`` / ``NAME.dat`` pair read with the ``comtrade`` package.

The pair carries its own time axis and the units of its analog channels; channels are named
by their ids (or taken by 0-based index).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from compliance.recordings.column_map import ColumnMap, ColumnSpec
from compliance.errors import InputError
from compliance.recordings.columns import RecordingSource, column_position

__all__ = ["partner_file", "read_comtrade"]


def partner_file(path: Path, suffix: str) -> Path | None:
    """The file beside ``path`` with the same stem and ``suffix`` (either case), if it exists."""
    for s in (suffix, suffix.upper()):
        p = path.with_suffix(s)
        if p.is_file():
            return p
    return None


def read_comtrade(path: Path, cmap: ColumnMap | None) -> RecordingSource:
    """Read a COMTRADE pair (given by its ``.cfg`` or ``.dat``) into raw float channels.

    Raises
    ------
    InputError
        Half a pair, a pair the ``comtrade`` package cannot read, an unknown channel.
    """
    import comtrade

    cfg = path if path.suffix.lower() == ".cfg" else partner_file(path, ".cfg")
    dat = partner_file(path, ".dat") if cfg is not None else None
    if cfg is None or dat is None:
        raise InputError(f"{path}: a COMTRADE recording needs both NAME.cfg and NAME.dat beside each other")
    rec = comtrade.Comtrade(ignore_warnings=True)
    try:
        rec.load(str(cfg), str(dat))
        time = np.asarray(rec.time, dtype=float)
        channels = [np.asarray(a, dtype=float) for a in rec.analog]
    except Exception as exc:  # the comtrade package raises bare Exceptions on bad files
        raise InputError(f"{cfg}: not a readable COMTRADE pair ({exc.__class__.__name__}: {exc})") from None
    ids = [str(n).strip() for n in rec.analog_channel_ids]
    units = [str(ch.uu).strip() or None for ch in rec.cfg.analog_channels]

    def get(spec: ColumnSpec):
        j = column_position(spec, ids, str(cfg), "analog channel", f"there are {len(ids)}", "channels")
        return channels[j], units[j]

    extra = {"station_name": str(rec.station_name).strip(), "recording_device": str(rec.rec_dev_id).strip()}
    if rec.start_timestamp is not None:
        extra["start_timestamp"] = rec.start_timestamp.isoformat()
    return RecordingSource(ids, get, lambda i: f"sample {i + 1}", time=time, extra=extra)

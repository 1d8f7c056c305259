"""The files of a COMTRADE recording (IEEE C37.111-1999/2013) and their data checked against the ``.cfg``.

A recording is a ``NAME.cfg`` / ``NAME.dat`` pair or, in the 2013 edition, one ``NAME.cff``
holding the sections ``--- file type: CFG ---``, ``INF``, ``HDR`` and
``--- file type: DAT BINARY: <bytes> ---`` (or ``DAT ASCII``). This module finds the parts and
refuses data the ``.cfg`` does not describe (the ``comtrade`` package would silently read a
short ``.dat`` as zeros, or binary data declared ASCII as garbage):

- a ``.dat`` shorter (or longer) than the samples the ``.cfg`` declares (its last ``endsamp``);
- binary bytes in data declared ``ASCII``;
- an ASCII line with the wrong number of fields.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from compliance.errors import InputError

__all__ = ["ComtradeParts", "DataLayout", "check_data", "load_parts", "partner_file"]

# bytes per value of the binary file types (C37.111-2013 clause 8.5): sample number and time stamp are 4 bytes
VALUE_BYTES = {"BINARY": 2, "BINARY32": 4, "FLOAT32": 4}
_CFF_HEADER = re.compile(rb"^--- *file type: *([A-Za-z]+)(?: +([A-Za-z0-9]+))?(?: *: *(\d+))? *---[ \t]*\r?$", re.M)


@dataclass(frozen=True)
class ComtradeParts:
    """The configuration text and the raw data bytes of one recording, and where they came from."""

    cfg_text: str
    data: bytes
    cfg_where: str  # "X.cfg" or "X.cff: CFG section", for messages
    data_where: str
    form: str  # "pair" or "cff"


@dataclass(frozen=True)
class DataLayout:
    """What the ``.cfg`` declares about the data: file type, samples, channels."""

    file_type: str  # ASCII, BINARY, BINARY32, FLOAT32
    samples: int
    analog: int
    status: int

    @property
    def row_bytes(self) -> int:
        """Bytes of one binary sample: number, time stamp, analog values, 16-bit status words."""
        return 8 + self.analog * VALUE_BYTES[self.file_type] + 2 * ((self.status + 15) // 16)


def partner_file(path: Path, suffix: str) -> Path | None:
    """The file beside ``path`` with the same stem and ``suffix`` (either case), if it exists."""
    for s in (suffix, suffix.upper()):
        p = path.with_suffix(s)
        if p.is_file():
            return p
    return None


def _text(raw: bytes) -> str:
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        return raw.decode("latin-1")  # 1999 files are plain ASCII; some devices write Latin-1 names


def load_parts(path: Path) -> ComtradeParts:
    """The ``.cfg`` text and ``.dat`` bytes of the recording ``path`` names (``.cfg``, ``.dat`` or ``.cff``).

    Raises
    ------
    InputError
        Half a pair; a ``.cff`` without a CFG or DAT section, or whose binary section is
        shorter than its header's byte count.
    """
    if path.suffix.lower() == ".cff":
        return _cff_parts(path)
    cfg = path if path.suffix.lower() == ".cfg" else partner_file(path, ".cfg")
    dat = partner_file(path, ".dat") if cfg is not None else None
    if cfg is None or dat is None:
        raise InputError(f"{path}: a COMTRADE recording needs both NAME.cfg and NAME.dat beside each other "
                         "(or the 2013 single file NAME.cff)")
    return ComtradeParts(_text(cfg.read_bytes()), dat.read_bytes(), str(cfg), str(dat), "pair")


def _cff_parts(path: Path) -> ComtradeParts:
    raw = path.read_bytes()
    sections: dict[str, tuple[str | None, bytes]] = {}
    pos = 0
    while True:
        m = _CFF_HEADER.search(raw, pos)
        if m is None:
            break
        kind, ftype, count = m.group(1).decode().upper(), m.group(2), m.group(3)
        start = m.end() + (1 if raw[m.end():m.end() + 1] == b"\n" else 0)
        if kind == "DAT" and ftype is not None and ftype.decode().upper() != "ASCII" and count is not None:
            n = int(count)
            body = raw[start:start + n]
            if len(body) < n:
                raise InputError(f"{path}: DAT section: the header declares {n} bytes but the file ends after "
                                 f"{len(body)}; the .cff is cut short")
            pos = start + n
        else:
            nxt = _CFF_HEADER.search(raw, start)
            body = raw[start:nxt.start() if nxt else len(raw)]
            pos = nxt.start() if nxt else len(raw)
        sections[kind] = (ftype.decode().upper() if ftype else None, body)
    for need in ("CFG", "DAT"):
        if need not in sections:
            raise InputError(f"{path}: a .cff needs a '--- file type: {need} ---' section (IEEE C37.111-2013 "
                             f"single-file form); found: {', '.join(sections) or 'no section header'}")
    return ComtradeParts(_text(sections["CFG"][1]), sections["DAT"][1],
                         f"{path}: CFG section", f"{path}: DAT section", "cff")


def check_data(parts: ComtradeParts, layout: DataLayout) -> bytes:
    """The data, checked against the layout the ``.cfg`` declares; ASCII data comes back without blank lines.

    Raises
    ------
    InputError
        Naming the cause: binary data declared ASCII, a ``.dat`` shorter or longer than the
        ``.cfg`` declares, an ASCII line with the wrong number of fields.
    """
    where, data, n = parts.data_where, parts.data, layout.samples
    if layout.file_type not in VALUE_BYTES and layout.file_type != "ASCII":
        raise InputError(f"{parts.cfg_where}: data file type '{layout.file_type}'; expected ASCII, BINARY, "
                         "BINARY32 or FLOAT32 (IEEE C37.111-2013)")
    if layout.file_type == "ASCII":
        return _check_ascii(parts, layout)
    size, row = len(data), layout.row_bytes
    if size == n * row:
        return data
    whole = size // row
    relation = "shorter than" if size < n * row else "longer than"
    raise InputError(
        f"{where}: the .dat is {relation} the .cfg declares: {size} bytes = {whole} whole sample(s)"
        f"{f' + {size % row} byte(s)' if size % row else ''} of {row} bytes ({layout.file_type}, {layout.analog} "
        f"analog + {layout.status} status channels), but {parts.cfg_where} declares {n} samples ({n * row} bytes); "
        "the file was cut (or the .cfg belongs to another recording)")


def _check_ascii(parts: ComtradeParts, layout: DataLayout) -> bytes:
    where, data, n = parts.data_where, parts.data, layout.samples
    bad = re.search(rb"[\x00-\x08\x0e-\x19\x7f-\xff]", data.rstrip(b"\x1a"))  # 0x1A: DOS end-of-file mark
    if bad is not None:
        raise InputError(
            f"{where}: binary data declared ASCII: byte 0x{data[bad.start()]:02X} at offset {bad.start()} is not "
            f"text, but {parts.cfg_where} says the data file type is ASCII; set the file type line of the .cfg to "
            "what the device wrote (BINARY, BINARY32 or FLOAT32)")
    lines = [ln for ln in data.replace(b"\x1a", b"").decode("ascii").splitlines() if ln.strip()]
    if len(lines) != n:
        relation = "shorter than" if len(lines) < n else "longer than"
        raise InputError(f"{where}: the .dat is {relation} the .cfg declares: {len(lines)} sample line(s), but "
                         f"{parts.cfg_where} declares {n} samples; the file was cut (or the .cfg belongs to another "
                         "recording)")
    fields = 2 + layout.analog + layout.status
    for i, line in enumerate(lines):
        if line.count(",") + 1 != fields:
            raise InputError(f"{where}: sample line {i + 1}: {line.count(',') + 1} fields, the .cfg declares {fields} "
                             f"(sample number, time stamp, {layout.analog} analog, {layout.status} status)")
    return "\n".join(lines).encode("ascii")

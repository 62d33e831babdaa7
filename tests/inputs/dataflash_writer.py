"""A tiny DataFlash (.bin) writer for tests: FMT records, then messages laid out by them.

Written from the format's description (``0xA3 0x95 <type>`` headers; FMT type 128 with
``Type B, Length B, Name n, Format N, Columns Z``), not with pymavlink, so that reading it back
through pymavlink checks our reader against an independent writer.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence
from pathlib import Path

HEAD = b"\xa3\x95"
_STRUCT = {"b": "b", "B": "B", "h": "h", "H": "H", "i": "i", "I": "I", "f": "f", "d": "d", "q": "q", "Q": "Q",
           "n": "4s", "N": "16s", "Z": "64s"}  # fmt: skip


class DataflashWriter:
    def __init__(self) -> None:
        self.out = bytearray()
        self.formats: dict[str, tuple[int, str]] = {}
        self._fmt(0x80, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns")

    def _fmt(self, type_id: int, name: str, fmt: str, columns: str) -> None:
        length = 3 + struct.calcsize("<" + "".join(_STRUCT[c] for c in fmt))
        self.formats[name] = (type_id, fmt)
        body = struct.pack("<BB4s16s64s", type_id, length, name.encode(), fmt.encode(), columns.encode())
        self.out += HEAD + bytes([0x80]) + body

    def define(self, name: str, fmt: str, columns: Sequence[str], type_id: int | None = None) -> None:
        """Declare a message (an FMT record); its type id is the next free one unless given."""
        self._fmt(0x40 + len(self.formats) if type_id is None else type_id, name, fmt, ",".join(columns))

    def write(self, name: str, *values: object) -> None:
        type_id, fmt = self.formats[name]
        packed = [v.encode() if isinstance(v, str) else v for v in values]
        self.out += HEAD + bytes([type_id]) + struct.pack("<" + "".join(_STRUCT[c] for c in fmt), *packed)

    def save(self, path: Path) -> Path:
        path.write_bytes(bytes(self.out))
        return path


def battery_log(
    path: Path,
    params: dict[str, float],
    rows: Sequence[tuple[float, int, float, float, float]],
    arming: Sequence[tuple[float, bool]],
) -> Path:
    """A log with PARM records, ARM records and BAT records (t s, instance, volts, amps, mAh used),
    written in time order."""
    w = DataflashWriter()
    w.define("PARM", "QNf", ("TimeUS", "Name", "Value"))
    w.define("ARM", "QBIb", ("TimeUS", "ArmState", "ArmChecks", "Method"))
    w.define("BAT", "QBfffffffBB", ("TimeUS", "Inst", "Volt", "VoltR", "Curr", "CurrTot", "EnrgTot", "Temp", "Res",
                                    "RemPct", "H"))  # fmt: skip
    for name, value in params.items():
        w.write("PARM", 0, name, float(value))
    events: list[tuple[float, int, tuple[object, ...]]] = []
    for t, armed in arming:
        events.append((t, 0, ("ARM", int(t * 1e6), int(armed), 0, 0)))
    for t, inst, volts, amps, used in rows:
        events.append((t, 1, ("BAT", int(t * 1e6), inst, volts, volts, amps, used, 0.0, 25.0, 0.0, 0, 1)))
    for _, _, (name, *values) in sorted(events, key=lambda e: (e[0], e[1])):
        w.write(str(name), *values)
    return w.save(path)

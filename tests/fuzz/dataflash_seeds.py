"""Small DataFlash seeds cut from real logs: every format record kept, and the first few records of each type
the battery-data layer reads (batteries, arming, events, modes, GPS time, parameters, messages, errors), in
their order in the log.

A whole real log is mostly records the layer walks past: fuzzing it ran six inputs a second, so the long
run's 100,000 inputs took hours. A thinned log keeps every record shape the layer parses and every way they
can be damaged, at a tenth of the size. Built from ../shared/corpus when the fuzzers start; never committed.
"""

from __future__ import annotations

from pathlib import Path

from pymavlink import DFReader

# the types the DataFlash layer reads (codegen/inputs/dataflash/log.py), and the formats behind them
KEPT = frozenset(
    {"FMT", "FMTU", "UNIT", "MULT", "BAT", "BATT", "CURR", "CUR2", "ARM", "EV", "GPS", "PARM", "MSG", "MODE", "ERR"}
    | {f"BAT{n}" for n in range(2, 10)}
    | {"CURR2"}
)
FORMATS = frozenset({"FMT", "FMTU", "UNIT", "MULT"})
PER_TYPE = 24


def thinned(path: Path, per_type: int = PER_TYPE) -> bytes:
    """The log at ``path`` with every format record and the first ``per_type`` records of each kept type."""
    data = path.read_bytes()
    reader = DFReader.DFReader_binary(str(path))
    kept: list[bytes] = []
    counts: dict[str, int] = {}
    while True:
        start = reader.offset
        msg = reader.recv_msg()
        if msg is None:
            break
        kind = msg.get_type()
        if kind not in KEPT:
            continue
        counts[kind] = counts.get(kind, 0) + 1
        if kind in FORMATS or counts[kind] <= per_type:
            kept.append(data[start : reader.offset])
    return b"".join(kept)

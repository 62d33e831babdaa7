"""Text DataFlash logs (``.log``: ``FMT, 128, 89, FMT, BBnNZ, ...`` lines, as Mission Planner and
ArduPilot 3.0's log download wrote them), read through pymavlink's ``DFReader_text``.

ArduPilot 3.0 text logs start with a few banner lines (``ArduCopter V3.0.1 (5c6503e2)``) before
the first ``FMT`` line, so the check looks for a ``FMT,`` line in the first KiB.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

HEAD_BYTES = 1024


def is_text_dataflash(head: bytes) -> bool:
    """True when one of the first lines of ``head`` is a ``FMT,`` line."""
    return any(line.lstrip().startswith((b"FMT,", b"FMT ,")) for line in head[:HEAD_BYTES].splitlines())


def open_text_reader(path: Path) -> Any:
    from pymavlink import DFReader

    return DFReader.DFReader_text(str(path), zero_time_base=True)

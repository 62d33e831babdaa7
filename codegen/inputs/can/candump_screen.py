"""candump's screen output (``candump can0``, ``candump -ta can0``): what people paste from a terminal.

Each frame is a line ``[(stamp)]  <interface>  <id>  [<length>]  <byte> <byte> ...`` with, after the bytes, the
ASCII column of ``-a`` or anything a person appended; an identifier of more than three hex digits is extended.
python-can reads only candump's ``-l`` log form (``(stamp) can0 ID#DATA``), so this small reader takes the screen
form. A frame's length must match its bytes and stay within classic CAN's 8 (the screen form has no FD flags).
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

from ...errors import cannot_read
from ..records import InputError
from .reassembly import Frame

MAX_LINE = 4096  # a screen line is under 200 characters; a longer one is not candump's
_LINE = re.compile(
    r"\s*(?:\((?P<stamp>\d+\.\d+)\)\s+)?(?P<iface>\S+)\s+(?P<id>[0-9A-Fa-f]{1,8})\s+\[(?P<dlc>\d)\]"
    r"(?P<data>(?:\s+[0-9A-Fa-f]{2})*)"
)


def screen_stamp(line: str) -> float | bool | None:
    """False if ``line`` is not a candump screen frame; else its stamp (None where candump printed none)."""
    match = _LINE.match(line)
    if match is None:
        return False
    return float(match["stamp"]) if match["stamp"] else None


def read_screen(path: Path, name: str) -> Iterator[Frame]:
    """The frames of a candump screen capture; an InputError naming the line for one that is not a frame."""
    t0: float | None = None
    index = 0
    try:
        f = path.open("r", encoding="utf-8", errors="replace")
    except OSError as exc:
        raise InputError(name, 0, cannot_read(exc)) from None
    with f:
        for number, line in enumerate(iter(lambda: f.readline(MAX_LINE + 1), ""), 1):
            if len(line) > MAX_LINE:
                raise InputError(name, number, f"expected a candump line (at most {MAX_LINE} characters)")
            if not line.strip():
                continue
            match = _LINE.match(line)
            if match is None:
                raise InputError(name, number, "expected a candump frame: '[(stamp)] can0 <id> [<n>] <bytes>'")
            data = bytes.fromhex(match["data"].replace(" ", "").replace("\t", ""))
            length = int(match["dlc"])
            if length > 8 or len(data) != length:
                raise InputError(name, number, f"expected {length} data bytes (at most 8), got {len(data)}")
            stamp = float(match["stamp"]) if match["stamp"] else float(index)
            t0 = stamp if t0 is None else t0
            ident = match["id"]
            yield Frame(index, stamp - t0, int(ident, 16), data, len(ident) > 3, False, match["iface"])
            index += 1

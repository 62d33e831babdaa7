"""The C walk of a ULog data section (_scan.c): see codegen/inputs/ulog/index.py."""

from collections.abc import Sequence
from typing import Any

def scan(buffer: Any, start: int, stop: int, known: bytes, out: Any, /) -> tuple[int, int]: ...
def gather(buffer: Any, offsets: Any, record_size: int, fields: Sequence[tuple[int, int, Any]], /) -> None: ...

"""The C walk of a ULog data section (_ulog_scan.c): see codegen/inputs/ulog_index.py."""

from typing import Any

def scan(buffer: Any, start: int, stop: int, known: bytes, out: Any, /) -> tuple[int, int]: ...

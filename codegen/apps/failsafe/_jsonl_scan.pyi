"""The C walk of a plain JSON Lines stream (_jsonl_scan.c): see codegen/apps/failsafe/jsonl_columns.py."""

from typing import Any

def scan(buffer: Any, literals: tuple[bytes, ...], slots: bytes, columns: Any, armed: Any, starts: Any, /) -> int: ...

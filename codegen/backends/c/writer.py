"""Write (or check) the C library on disk."""

from __future__ import annotations

from pathlib import Path

from ...ir import Schema
from .render import render_library

_SUFFIXES = (".h", ".c")


def generate_c(schema: Schema, out: Path, *, check: bool = False) -> tuple[list[str], list[str], list[str]]:
    """(written, removed, unchanged) relative paths; with ``check`` nothing is written."""
    files = render_library(schema)
    existing = (
        {p.relative_to(out).as_posix() for p in out.rglob("*") if p.suffix in _SUFFIXES} if out.is_dir() else set()
    )
    written, unchanged = [], []
    for rel, text in sorted(files.items()):
        target = out / rel
        data = text.encode("utf-8")
        if target.is_file() and target.read_bytes() == data:
            unchanged.append(rel)
            continue
        written.append(rel)
        if not check:
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(data)
    removed = sorted(existing - set(files))
    if not check:
        for rel in removed:
            (out / rel).unlink()
    return written, removed, unchanged

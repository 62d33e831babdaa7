"""Write (or check) the Rust crate on disk."""

from __future__ import annotations

from pathlib import Path

from ...ir import Schema
from .render import render_crate

_NOT_OURS = ("target", "Cargo.lock")  # cargo's output beside the crate, never rendered or removed


def generate_rust(schema: Schema, out: Path, *, check: bool = False) -> tuple[list[str], list[str], list[str]]:
    """(written, removed, unchanged) relative paths; with ``check`` nothing is written."""
    files = render_crate(schema)
    existing: set[str] = set()
    if out.is_dir():
        for p in out.rglob("*"):
            parts = p.relative_to(out).parts
            if p.is_file() and parts[0] not in _NOT_OURS:
                existing.add("/".join(parts))
    written: list[str] = []
    unchanged: list[str] = []
    for rel, text in files.items():
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

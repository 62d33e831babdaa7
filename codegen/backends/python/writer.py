"""Write (or check) a generated package on disk."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ...ir import Schema
from . import render_package


@dataclass(frozen=True)
class GenerateResult:
    written: tuple[str, ...]  # files created or changed
    removed: tuple[str, ...]  # files no longer generated
    unchanged: tuple[str, ...]

    @property
    def stale(self) -> tuple[str, ...]:
        return self.written + self.removed


def _existing(out: Path) -> set[str]:
    if not out.is_dir():
        return set()
    return {p.relative_to(out).as_posix() for p in out.rglob("*.py") if "__pycache__" not in p.parts}


def generate(schema: Schema, out: Path, *, check: bool = False) -> GenerateResult:
    """Render ``schema`` into the package folder ``out``; with ``check`` write nothing and only report."""
    files = render_package(schema)
    existing = _existing(out)
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
        _prune_empty_dirs(out)
    return GenerateResult(tuple(written), tuple(removed), tuple(unchanged))


def _prune_empty_dirs(out: Path) -> None:
    for d in sorted((p for p in out.rglob("*") if p.is_dir()), key=lambda p: len(p.parts), reverse=True):
        leftovers = [c for c in d.iterdir() if c.name != "__pycache__"]
        if not leftovers:
            for cache in d.glob("__pycache__"):
                for f in cache.iterdir():
                    f.unlink()
                cache.rmdir()
            d.rmdir()

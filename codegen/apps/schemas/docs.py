"""Writing the Markdown reference pages (``battgen docs``) into a folder, or checking them.

Only pages this command wrote (they start with the backend's MARKER line) are ever removed, so a
folder may hold hand-written pages beside the generated ones.
"""

from __future__ import annotations

from pathlib import Path

from ...backends.markdown import MARKER
from ...errors import BattgenError


def _ours(path: Path) -> bool:
    """Whether a Markdown file was written by this command (only those are ever removed)."""
    try:
        with path.open(encoding="utf-8") as stream:
            return stream.readline().rstrip("\n") == MARKER
    except (OSError, UnicodeDecodeError):
        return False


def write_docs(pages: dict[str, str], out: Path, *, check: bool) -> tuple[list[str], list[str], list[str]]:
    """(written, removed, unchanged) page names; with ``check`` nothing is written or removed."""
    written, unchanged = [], []
    for name, text in pages.items():
        target = out / name
        data = text.encode("utf-8")
        try:
            same = target.is_file() and target.read_bytes() == data
        except OSError:
            same = False
        if same:
            unchanged.append(name)
            continue
        written.append(name)
        if not check:
            try:
                out.mkdir(parents=True, exist_ok=True)
                target.write_bytes(data)
            except OSError as exc:
                raise BattgenError(f"{target}: cannot write: {exc.strerror or exc}") from None
    removed = sorted(p.name for p in out.glob("*.md") if p.name not in pages and _ours(p)) if out.is_dir() else []
    if not check:
        for name in removed:
            (out / name).unlink()
    return written, removed, unchanged

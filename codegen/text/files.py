"""Reading a text file as UTF-8 with errors at a file and line, and the path that names it in IR locations."""

from __future__ import annotations

from pathlib import Path

from ..errors import LocatedError, SchemaError, cannot_read


def display_path(path: Path, root: Path | None) -> str:
    """The path recorded in IR locations: relative to the schema root when under it (so output
    does not depend on where a checkout lives), otherwise as given; always with '/' separators."""
    if root is not None:
        try:
            return path.resolve().relative_to(root.resolve()).as_posix()
        except ValueError:
            pass
    return path.as_posix()


def read_text(path: Path, display: str, error: type[LocatedError] = SchemaError) -> str:
    """Read an input file as UTF-8, turning I/O and decoding failures into ``error`` (file and line)."""
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise error(display, 0, cannot_read(exc)) from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise error(display, line, "expected UTF-8 text") from None


def is_file(path: Path) -> bool:
    """Whether ``path`` is a file, for a path built from schema text: a name too long for the file
    system (or otherwise unusable) is simply not a file, where ``Path.is_file`` would raise."""
    try:
        return path.is_file()
    except (OSError, ValueError):  # ENAMETOOLONG; ValueError for an embedded NUL
        return False

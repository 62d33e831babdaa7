"""Reading a text file as UTF-8 with errors at a file and line, and the path that names it in IR locations."""

from __future__ import annotations

from pathlib import Path

from ..errors import LocatedError, SchemaError, cannot_read

# bytes of a whole-file input (a parameter file, a .dts, a .dtb, a schema): the largest real one is a few MB
# (ArduPilot's apm.pdef.xml, ~3 MB); a bigger file is refused before it is read, not held in memory
MAX_WHOLE_FILE = 64 * 1024 * 1024


def display_path(path: Path, root: Path | None) -> str:
    """The path recorded in IR locations: relative to the schema root when under it (so output
    does not depend on where a checkout lives), otherwise as given; always with '/' separators."""
    if root is not None:
        try:
            return path.resolve().relative_to(root.resolve()).as_posix()
        except ValueError:
            pass
    return path.as_posix()


def read_whole(path: Path, display: str, error: type[LocatedError], what: str) -> bytes:
    """An input file read whole, at most :data:`MAX_WHOLE_FILE` bytes of it: a larger one (or an endless one,
    ``/dev/zero``) is ``error`` at line 0 saying it expected ``what``, and costs no more than the limit."""
    try:
        with path.open("rb") as f:
            data = f.read(MAX_WHOLE_FILE + 1)
    except OSError as exc:
        raise error(display, 0, cannot_read(exc)) from None
    if len(data) > MAX_WHOLE_FILE:
        raise error(display, 0, f"expected {what} of at most {MAX_WHOLE_FILE} bytes, found a larger file")
    return data


def read_text(path: Path, display: str, error: type[LocatedError] = SchemaError, what: str = "a text file") -> str:
    """Read an input file as UTF-8 (:func:`read_whole`), turning I/O and decoding failures into ``error`` (file
    and line)."""
    data = read_whole(path, display, error, what)
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

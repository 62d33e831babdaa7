"""Reading MAVLink dialect files and everything they <include>, each once, in include order.

Each file is read as UTF-8, pre-scanned (:mod:`.scan`: no DTDs, only literal enum values, since
pymavlink eval()s them), then parsed by pymavlink's own mavparse.MAVXML from a private copy of
exactly the bytes we checked, with its stdout captured and its exceptions and exits turned into
SchemaError. Includes resolve relative to the including file; cycles and missing files are errors
at the <include> line.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import tempfile
from pathlib import Path

from ...errors import SchemaError
from ...text.files import display_path
from ...text.xml import read_xml
from .build import LoadedFile
from .scan import scan


def read_dialects(paths: list[Path], root: Path | None) -> list[LoadedFile]:
    """The files named and every file they include, included files before their includer."""
    with tempfile.TemporaryDirectory(prefix="battgen-mavlink-") as tmp:
        reader = _Reader(root, Path(tmp))
        for path in paths:
            reader.load(path)
    return list(reader.files.values())


def _mavparse(data: bytes, name: str, display: str, workdir: Path) -> object:
    from pymavlink.generator import mavparse

    copy = workdir / name
    copy.write_bytes(data)
    out = io.StringIO()
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
            return mavparse.MAVXML(str(copy), mavparse.PROTOCOL_2_0)
    except (Exception, SystemExit) as exc:
        text = str(exc).replace(str(copy), display)
        m = re.search(r":(\d+)\s*$", text)
        line = int(m.group(1)) if m else getattr(exc, "lineno", 1)
        raise SchemaError(
            display, line, f"expected a dialect pymavlink accepts ({type(exc).__name__}: {text})"
        ) from None
    finally:
        copy.unlink(missing_ok=True)


class _Reader:
    def __init__(self, root: Path | None, workdir: Path) -> None:
        self.root = root
        self.workdir = workdir
        self.files: dict[Path, LoadedFile] = {}  # included files before their includer

    def load(self, path: Path, chain: tuple[Path, ...] = ()) -> None:
        key = path.resolve()
        if key in self.files:
            return
        display = display_path(path, self.root)
        data = read_xml(path, display)
        scanned = scan(data, display)
        chain += (key,)
        for text, line in scanned.includes:
            included = Path(os.path.normpath(path.parent / text))
            if included.resolve() in chain:
                raise SchemaError(
                    display, line, f"expected an include that does not lead back here; {text} closes an include cycle"
                )
            if not included.is_file():
                raise SchemaError(
                    display,
                    line,
                    f"expected {text} to exist relative to this file ({display_path(included, self.root)})",
                )
            self.load(included, chain)
        mavxml = _mavparse(data, path.name, display, self.workdir)
        self.files[key] = LoadedFile(path, display, scanned, mavxml)

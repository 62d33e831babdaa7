"""MAVLink XML frontend: dialect files (with their <include>s) -> IR.

Each file is pre-scanned by mavlink_scan (no DTDs, only literal enum values: pymavlink eval()s
them), then parsed by pymavlink's own mavparse.MAVXML from a private copy of exactly the bytes
we checked, with its stdout captured and its exceptions/exits turned into SchemaError.
Includes resolve relative to the including file; each file is read once; cycles and missing
files are errors at the <include> line.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import tempfile
from pathlib import Path

from ...errors import SchemaError
from ...ir import Schema
from ...text.files import display_path, read_text
from . import scan as mavlink_scan
from .build import LoadedFile, build

__all__ = ["parse_dir", "parse_file"]


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


class _Loader:
    def __init__(self, root: Path | None, workdir: Path) -> None:
        self.root = root
        self.workdir = workdir
        self.files: dict[Path, LoadedFile] = {}  # included files before their includer

    def load(self, path: Path, chain: tuple[Path, ...] = ()) -> None:
        key = path.resolve()
        if key in self.files:
            return
        display = display_path(path, self.root)
        data = read_text(path, display).encode("utf-8")
        scanned = mavlink_scan.scan(data, display)
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


def _parse(paths: list[Path], root: Path | None) -> Schema:
    with tempfile.TemporaryDirectory(prefix="battgen-mavlink-") as tmp:
        loader = _Loader(root, Path(tmp))
        for path in paths:
            loader.load(path)
    return build(list(loader.files.values()))


def parse_file(path: Path, *, root: Path | None = None) -> Schema:
    """One dialect file and everything it includes."""
    return _parse([path], root)


def parse_dir(root: Path) -> Schema:
    """Every *.xml below root (sorted); shared includes are read once."""
    return _parse(sorted(p for p in root.rglob("*.xml") if p.is_file()), root)

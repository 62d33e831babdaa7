"""Reading MAVLink dialect files and everything they <include>, each once, in include order.

Each file is read as UTF-8, pre-scanned (:mod:`.scan`: no DTDs, only literal enum values, since
pymavlink eval()s them), then parsed by pymavlink's own mavparse.MAVXML from a private copy of
exactly the bytes we checked, with its stdout captured and its exceptions and exits turned into
SchemaError. Includes resolve relative to the including file, then in each folder of the user's
search path (``--include-path``); a file outside the schema folder and the search path is refused
(an include may not read /etc/passwd or wander up with ``../``). Cycles and missing or refused files
are errors at the <include> line.

A folder (or several files) is read whole even when files in it are bad: every file's errors come in
one report (an ErrorList), a file that includes a bad file reporting its own errors too; a bad file
included from several places is reported once.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import tempfile
from collections.abc import Sequence
from pathlib import Path

from ...errors import BattgenError, ErrorCollector, SchemaError
from ...text.files import display_path, is_file
from ...text.xml import read_xml
from .build import LoadedFile
from .scan import scan


def read_dialects(
    paths: list[Path], root: Path | None, include_paths: Sequence[Path] = (), errors: ErrorCollector | None = None
) -> list[LoadedFile]:
    """The files named and every file they include, included files before their includer.

    Includes must stay inside ``root`` (for single files without a root: the folder of each file
    named) or one of ``include_paths``, which are also searched for includes not found beside the
    including file. The errors of every bad file are raised together, or with ``errors`` collected
    there while the files that read are returned.
    """
    found = errors if errors is not None else ErrorCollector()  # every bad file of the run, not the first
    with tempfile.TemporaryDirectory(prefix="battgen-mavlink-") as tmp:
        reader = _Reader(root, Path(tmp), tuple(include_paths))
        for path in paths:
            reader.allowed = (
                (root if root is not None else path.parent).resolve(),
                *(p.resolve() for p in include_paths),
            )
            with found.step():
                reader.load(path)
    if errors is None:
        found.raise_if_any()
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
    def __init__(self, root: Path | None, workdir: Path, include_paths: tuple[Path, ...]) -> None:
        self.root = root
        self.workdir = workdir
        self.include_paths = include_paths
        self.allowed: tuple[Path, ...] = ()  # the folders includes may read from
        self.files: dict[Path, LoadedFile] = {}  # included files before their includer
        self.failed: dict[Path, BattgenError] = {}  # bad files, each read (and reported) once

    def load(self, path: Path, chain: tuple[Path, ...] = ()) -> None:
        key = path.resolve()
        if key in self.files:
            return
        if key in self.failed:
            raise self.failed[key]
        try:
            self.files[key] = self._read(path, (*chain, key))
        except BattgenError as exc:
            self.failed[key] = exc
            raise

    def _read(self, path: Path, chain: tuple[Path, ...]) -> LoadedFile:
        """One file, after everything it includes; its includes' errors and its own in one report."""
        display = display_path(path, self.root)
        data = read_xml(path, display)
        scanned = scan(data, display)
        found = ErrorCollector()
        for text, line in scanned.includes:
            with found.step():
                included = self._resolve(path, text, display, line)
                if included.resolve() in chain:
                    raise SchemaError(
                        display,
                        line,
                        f"expected an include that does not lead back here; {text} closes an include cycle",
                    )
                self.load(included, chain)
        with found.step():
            mavxml = _mavparse(data, path.name, display, self.workdir)
        found.raise_if_any()
        return LoadedFile(path, display, scanned, mavxml)

    def _resolve(self, path: Path, text: str, display: str, line: int) -> Path:
        """The file an <include> names: beside the including file, else in the search path; inside
        the schema folder or the search path in either case."""
        candidates = [Path(os.path.normpath(path.parent / text))]
        candidates += [Path(os.path.normpath(folder / text)) for folder in self.include_paths]
        # containment first (symbolic links followed): nothing outside is even looked at
        found = next((c for c in candidates if self._inside(c) and is_file(c)), None)
        if found is not None:
            return found
        if not self._inside(candidates[0]):
            raise SchemaError(
                display,
                line,
                f"expected an include inside the schema folder ({self.allowed[0]}); {text} is outside it "
                "(allow its folder with --include-path)",
            )
        raise SchemaError(
            display,
            line,
            f"expected {text} to exist relative to this file ({display_path(candidates[0], self.root)})"
            + (" or in the --include-path folders" if self.include_paths else ""),
        )

    def _inside(self, candidate: Path) -> bool:
        real = candidate.resolve()
        return any(real.is_relative_to(folder) for folder in self.allowed)

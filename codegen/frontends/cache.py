"""A schema folder's IR kept between runs, keyed by what it was made from.

Parsing the bundled schemas (pydsdl for the Cyphal types, the jsonschema check of the mappings, the
MAVLink XML) costs more than most commands' own work, and every command reads them. The IR is a
pure function of the folder's files, the ``only`` selection and the code that parses them, so a
pickle of it is stored under a key hashing all three: the content of every file below the folder,
the selection, battgen's version (the package face's source), the size and modification time of
every source file of the frontends and the IR (a checkout being edited changes them), and the
Python that pickled it. A file whose key does not match is never read (a stale or foreign cache
parses afresh); one is written to a temporary name and renamed into place, so a reader never sees
half of it. Errors are not cached: a folder that fails to parse fails on every run, with every error.
"""

from __future__ import annotations

import hashlib
import io
import math
import os
import pickle
import sys
from collections.abc import Collection
from pathlib import Path

from ..ir import Schema

_CODE_DIRS = (Path(__file__).resolve().parent, Path(__file__).resolve().parents[1] / "ir")
# the package face, whose __version__ is battgen's version (read as bytes: importing it from here would make the
# frontends depend on the package face, which names the backends)
_VERSION_FILE = Path(__file__).resolve().parents[1] / "__init__.py"
_MAGIC = b"battgen-ir-cache 2\n"
_NAN_ID = "nan"


class _Pickler(pickle.Pickler):
    # The frontends give every NaN of the IR as the one object math.nan, so that equal ops and sentinels
    # compare equal (tuples compare members by identity first, and NaN != NaN); pickle would write each as a
    # float of its own and read back distinct objects, making a cached IR unequal to a parsed one.
    def persistent_id(self, obj: object) -> str | None:
        return _NAN_ID if isinstance(obj, float) and obj != obj else None


class _Unpickler(pickle.Unpickler):
    def persistent_load(self, pid: object) -> object:
        if pid == _NAN_ID:
            return math.nan
        raise pickle.UnpicklingError(f"unknown persistent id {pid!r}")


def _tree(root: Path, suffix: str = "") -> list[Path]:
    out: list[Path] = []
    for folder, dirs, files in os.walk(root):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__")
        out.extend(Path(folder, f) for f in sorted(files) if f.endswith(suffix))
    return out


def cache_key(folder: Path, only: Collection[str] | None = None) -> str:
    """The hash naming the IR of ``folder`` read with ``only``: its files' content, the code reading them."""
    digest = hashlib.sha256(_MAGIC)
    digest.update(hashlib.sha256(_VERSION_FILE.read_bytes()).digest())
    digest.update(f"{sys.implementation.cache_tag}\0{sorted(only) if only else None}\0".encode())
    for code_dir in _CODE_DIRS:
        for path in _tree(code_dir, ".py"):
            st = path.stat()
            digest.update(f"{path.relative_to(code_dir)}\0{st.st_size}\0{st.st_mtime_ns}\0".encode())
    for path in _tree(folder):
        digest.update(f"{path.relative_to(folder).as_posix()}\0".encode())
        digest.update(hashlib.sha256(path.read_bytes()).digest())
    return digest.hexdigest()


def _read(file: Path, key: str) -> Schema | None:
    try:
        data = file.read_bytes()
    except OSError:
        return None
    head = _MAGIC + key.encode() + b"\n"
    if not data.startswith(head):  # a different key (a clash of names cut short) or a torn file
        return None
    try:
        schema = _Unpickler(io.BytesIO(data[len(head) :])).load()
    except Exception:  # an unreadable cache is only a cache: parse afresh
        return None
    return schema if isinstance(schema, Schema) else None


def _write(file: Path, key: str, schema: Schema) -> None:
    import tempfile  # here: a run that finds the IR stored writes nothing

    try:
        file.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=file.name, suffix=".tmp", dir=file.parent)
        try:
            with os.fdopen(fd, "wb") as out:
                out.write(_MAGIC + key.encode() + b"\n")
                _Pickler(out, protocol=pickle.HIGHEST_PROTOCOL).dump(schema)
            os.replace(tmp, file)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
    except OSError:
        pass  # a read-only or full cache folder: the IR was parsed, the run goes on without storing it


def load_cached(folder: Path, cache_dir: Path, *, only: Collection[str] | None = None) -> Schema:
    """``load([folder], only=only)``, read from ``cache_dir`` when an earlier run stored the same key."""
    key = cache_key(folder, only)
    file = cache_dir / f"ir-{key[:32]}.pickle"
    schema = _read(file, key)
    if schema is None:
        from .loader import load  # every frontend, imported only when there is something to parse

        schema = load([folder], only=only)
        _write(file, key, schema)
    return schema

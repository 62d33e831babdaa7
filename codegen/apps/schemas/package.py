"""Locating the generated package, its modules and the class that models a message.

The one place that knows where generated code comes from: the checkout battgen is installed from
(:func:`project_root`, found from this package's location, never from the current folder, which
holds a user's data and no code battgen may run) holds ``schemas/`` and the committed
``generated/``; the bundled schemas use that package; any other schema folder (``--schemas``) is
generated into a temporary package once per process and imported from there; only ``battgen
convert --package NAME`` imports a package by name, as asked, from the current folder.
"""

from __future__ import annotations

import atexit
import hashlib
import importlib
import importlib.util
import os
import sys
from collections.abc import Collection, Iterable
from pathlib import Path
from types import ModuleType
from typing import cast

from ...backends.python import naming
from ...errors import BattgenError
from ...frontends.cache import load_cached
from ...inputs.model import MessageClass
from ...ir import Message, Schema

_PACKAGES: dict[str, ModuleType] = {}


_INSTALLED_ROOT = Path(__file__).resolve().parents[3]  # the checkout (or site-packages) holding codegen/


def project_root() -> Path:
    """The checkout battgen runs from, holding codegen/, schemas/ and generated/ (whatever the current folder)."""
    return _INSTALLED_ROOT


def bundled_schemas() -> Path:
    """The schema folder used when none is given."""
    return project_root() / "schemas"


def cache_dir() -> Path:
    """Where the parsed IR of the bundled schemas is kept between runs: ``$XDG_CACHE_HOME/battgen``
    (default ``~/.cache/battgen``)."""
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "battgen"


def load_schemas(schema_dir: Path, *, only: Collection[str] | None = None) -> Schema:
    """``load([schema_dir], only=only)``; the bundled schemas from the IR cache (:mod:`codegen.frontends.cache`),
    so a command does not parse and check them again on every run (a folder of the user's is read afresh)."""
    if schema_dir.resolve() == bundled_schemas().resolve():
        return load_cached(schema_dir, cache_dir(), only=only)
    from ...frontends.loader import load

    return load([schema_dir], only=only)


def _is_committed(schema_dir: Path, root: Path) -> bool:
    try:
        same = schema_dir.resolve() == (root / "schemas").resolve()
    except OSError:
        return False
    return same and (root / "generated" / "__init__.py").is_file()


def _import_from(folder: Path, name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(
        name, folder / "__init__.py", submodule_search_locations=[str(folder)]
    )
    if spec is None or spec.loader is None:
        raise BattgenError(f"{folder}: cannot import the generated package")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def _is_folder(locations: Iterable[str] | None, folder: Path) -> bool:
    return any(Path(p).resolve() == folder.resolve() for p in locations or ())


def _committed_package(folder: Path) -> ModuleType:
    # The importable ``generated`` only if it is this folder: found first, without running it (the
    # current folder, on sys.path under ``python -m``, may hold a stranger's ``generated/``).
    pkg = sys.modules.get("generated")
    if pkg is not None and _is_folder(getattr(pkg, "__path__", None), folder):
        return pkg
    if pkg is None:
        try:
            spec = importlib.util.find_spec("generated")
        except (ImportError, ValueError):
            spec = None
        if spec is not None and _is_folder(spec.submodule_search_locations, folder):
            return importlib.import_module("generated")
    digest = hashlib.sha256(str(folder.resolve()).encode()).hexdigest()[:12]
    return _import_from(folder, f"_battgen_generated_{digest}")


def _temporary_package(schema: Schema, key: str) -> ModuleType:
    digest = hashlib.sha256(key.encode()).hexdigest()[:12]
    name = f"_battgen_models_{digest}"
    import shutil  # here: the bundled schemas, what most runs read, need neither
    import tempfile

    tmp = Path(tempfile.mkdtemp(prefix="battgen-models-"))
    atexit.register(shutil.rmtree, tmp, True)
    from ...backends.python.writer import generate  # the code generator, for a folder other than the bundled one

    generate(schema, tmp / name)
    return _import_from(tmp / name, name)


def model_package(schema: Schema, schema_dir: Path, root: Path | None = None) -> ModuleType:
    """The generated package for ``schema`` (read from ``schema_dir``), imported once per process."""
    root = root if root is not None else project_root()
    key = str(schema_dir.resolve())
    pkg = _PACKAGES.get(key)
    if pkg is None:
        if _is_committed(schema_dir, root):
            pkg = _committed_package(root / "generated")
        else:
            pkg = _temporary_package(schema, key)
        _PACKAGES[key] = pkg
    return pkg


def bundled_package() -> ModuleType:
    """The committed package of the bundled schemas (the one installed with battgen), without reading the schemas."""
    folder = _INSTALLED_ROOT / "generated"
    key = f"committed:{folder}"
    pkg = _PACKAGES.get(key)
    if pkg is None:
        pkg = _PACKAGES[key] = _committed_package(folder)
    return pkg


def named_package(name: str | None) -> ModuleType:
    """A generated package by its import name, looked for in the current folder first (``convert
    --package``, a user's choice); None: the bundled one."""
    if name is None:
        return bundled_package()
    root = str(Path.cwd())
    if root not in sys.path:
        sys.path.insert(0, root)
    return importlib.import_module(name)


def package_module(package: ModuleType, name: str) -> ModuleType:
    """A module of a generated package: ``convert``, ``params``, ``_meta``..."""
    return importlib.import_module(f"{package.__name__}.{name}")


def data_error(package: ModuleType) -> type[Exception]:
    """The error a generated ``from_dict`` raises on data that does not fit (``_meta.DataError``)."""
    error = getattr(package_module(package, "_meta"), "DataError", ValueError)
    return cast(type[Exception], error)


def model_class(package: ModuleType, msg: Message) -> MessageClass:
    """The generated class of ``msg`` inside ``package``."""
    module = package_module(package, naming.module_path(msg))
    cls = getattr(module, naming.class_name(msg), None)
    if cls is None or getattr(cls, "QUALIFIED_NAME", None) != msg.qualified_name:
        raise BattgenError(
            f"the generated package {package.__name__} has no class for {msg.qualified_name}: run 'battgen generate'"
        )
    return cast(MessageClass, cls)

"""Finding a message by name and the generated class that models it.

The bundled schemas use the committed ``generated`` package; any other schema folder is
generated into a temporary package once per process and imported from there.
"""

from __future__ import annotations

import atexit
import hashlib
import importlib
import importlib.util
import shutil
import sys
import tempfile
from pathlib import Path
from types import ModuleType
from typing import Any

from ..backends.python import naming
from ..backends.python.writer import generate
from ..errors import BattgenError
from ..ir import Message, Schema

_PACKAGES: dict[str, ModuleType] = {}


def message_aliases(msg: Message) -> set[str]:
    """The names a user may give for ``msg``: its qualified name, every dotted suffix of it, the
    source name, the generated class name, and for devicetree bindings the compatible strings."""
    parts = msg.qualified_name.split(".")
    names = {".".join(parts[i:]) for i in range(len(parts))}
    names.update((msg.name, naming.class_name(msg)))
    if msg.devicetree is not None:
        names.update(msg.devicetree.compatible)
    return names


def resolve_message(schema: Schema, name: str) -> Message:
    """The message called ``name``: exact qualified name first, else an unambiguous short form."""
    for msg in schema.messages:
        if msg.qualified_name == name:
            return msg
    matches = [m for m in schema.messages if name in message_aliases(m)]
    if not matches:
        folded = name.casefold()
        matches = [m for m in schema.messages if folded in {a.casefold() for a in message_aliases(m)}]
    if len(matches) == 1:
        return matches[0]
    if matches:
        candidates = ", ".join(m.qualified_name for m in matches)
        raise BattgenError(f"message name {name!r} is ambiguous: it could be {candidates}")
    known = ", ".join(m.qualified_name for m in schema.messages)
    raise BattgenError(f"no message called {name!r} (known: {known})")


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


def _committed_package(folder: Path) -> ModuleType:
    try:
        pkg = importlib.import_module("generated")
        if any(Path(p).resolve() == folder.resolve() for p in getattr(pkg, "__path__", ())):
            return pkg
    except ImportError:
        pass
    digest = hashlib.sha256(str(folder.resolve()).encode()).hexdigest()[:12]
    return _import_from(folder, f"_battgen_generated_{digest}")


def _temporary_package(schema: Schema, key: str) -> ModuleType:
    digest = hashlib.sha256(key.encode()).hexdigest()[:12]
    name = f"_battgen_models_{digest}"
    tmp = Path(tempfile.mkdtemp(prefix="battgen-models-"))
    atexit.register(shutil.rmtree, tmp, True)
    generate(schema, tmp / name)
    return _import_from(tmp / name, name)


def model_package(schema: Schema, schema_dir: Path, root: Path) -> ModuleType:
    """The generated package for ``schema`` (read from ``schema_dir``), imported once per process."""
    key = str(schema_dir.resolve())
    pkg = _PACKAGES.get(key)
    if pkg is None:
        if _is_committed(schema_dir, root):
            pkg = _committed_package(root / "generated")
        else:
            pkg = _temporary_package(schema, key)
        _PACKAGES[key] = pkg
    return pkg


def model_class(package: ModuleType, msg: Message) -> Any:
    """The generated class of ``msg`` inside ``package``."""
    module = importlib.import_module(f"{package.__name__}.{naming.module_path(msg)}")
    cls = getattr(module, naming.class_name(msg), None)
    if cls is None or getattr(cls, "QUALIFIED_NAME", None) != msg.qualified_name:
        raise BattgenError(
            f"the generated package {package.__name__} has no class for {msg.qualified_name}: run 'battgen generate'"
        )
    return cls

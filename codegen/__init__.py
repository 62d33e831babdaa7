"""battgen: one IR for battery telemetry schemas (PX4 uORB, DroneCAN, devicetree, MAVLink, ArduPilot).

The package face: what a program driving battgen needs, re-exported from the layers that hold it.

    import codegen
    schema = codegen.load([Path("schemas")])        # frontends -> one IR (codegen.ir.Schema)
    codegen.generate(schema, Path("generated"))      # the Python backend writes the package

The layers, lowest first: ``ir`` (the model), ``errors``, ``text`` (safe reading of source text),
``frontends`` / ``backends`` / ``inputs`` (independent of each other), ``apps``, ``cli``;
docs/architecture.md describes them and pyproject.toml holds the import contract between them.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .errors import BattgenError, LocatedError, SchemaError

if TYPE_CHECKING:
    from .backends.python.writer import GenerateResult, generate
    from .frontends.loader import load
    from .ir import Message, Schema

__version__ = "0.1.0"

# Imported on first use (PEP 562): every `battgen` run imports this package, and a command that reads a log
# must not pay for the frontends and the code generator it never calls.
_LAZY = {
    "GenerateResult": "backends.python.writer",
    "generate": "backends.python.writer",
    "load": "frontends.loader",
    "Message": "ir",
    "Schema": "ir",
}


def __getattr__(name: str) -> Any:
    if name not in _LAZY:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    import importlib

    value = getattr(importlib.import_module(f"{__name__}.{_LAZY[name]}"), name)
    globals()[name] = value
    return value


__all__ = [
    "BattgenError",
    "GenerateResult",
    "LocatedError",
    "Message",
    "Schema",
    "SchemaError",
    "__version__",
    "generate",
    "load",
]

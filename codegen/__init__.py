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

from .backends.python.writer import GenerateResult, generate
from .errors import BattgenError, LocatedError, SchemaError
from .frontends.loader import load
from .ir import Message, Schema

__version__ = "0.1.0"

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

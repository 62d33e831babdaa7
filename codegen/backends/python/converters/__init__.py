"""Converter generator: the IR's mappings become ``generated/convert/``, plain Python functions.

Layout of the generated package:

- ``convert/_runtime.py``  the loss report and numeric helpers (copied from ``runtime/convert/_runtime.py``)
- ``convert/_cells.py``    the array algorithms the mappings name (copied from ``runtime/convert/_cells.py``)
- ``convert/_ardupilot.py`` ArduPilot's battery arithmetic, for the ardupilot policy (``runtime/convert/_ardupilot.py``)
- ``convert/_state.py``    ``BatteryState``'s base: plain data in and out (copied from ``runtime/convert/_state.py``)
- ``convert/_concepts.py`` ``BatteryState``: the shared concepts as a dataclass (SI units, None = unknown)
- ``convert/_map_<mapping>.py`` one function per direction of each mapping (``forward``/``backward``)
- ``convert/<endpoint>.py``  ``to_concepts`` / ``from_concepts`` for each format with a concept mapping
- ``convert/<a>_<b>.py``  ``a_to_b`` / ``b_to_a`` for every pair: each policy is a chain of
  mapping functions found at generation time (strict through the concepts, px4 and ardupilot
  through the firmware's own code paths); nothing is interpreted at run time.

Modules of this package: :mod:`.mapping_module` writes a mapping's functions, rule by rule through
:class:`~.function.FunctionBuilder` (the backend's implementation of the op contract,
:class:`~codegen.ir.mapping_visitor.OpVisitor`, from the emitter mixins :mod:`.numeric`,
:mod:`.choices`, :mod:`.cells`, :mod:`.devicetree`, :mod:`.messages`, :mod:`.px4`, :mod:`.px4_cells`,
:mod:`.ardupilot`);
:mod:`.routes` chains them into converters; :mod:`.concepts_module` writes ``BatteryState``.
Emitters write one statement a line, with literals from :mod:`..literals`; every module is then
formatted by ruff (:mod:`..formatting`), as the model modules are.
"""

from __future__ import annotations

from ....ir import Concept, Endpoint, Mapping, Message, Schema
from ..extensions import Contribution
from ..runtime import copied
from ..views import ClassView, ModuleContext
from .concepts_module import concepts_module
from .mapping_module import Edge, mapping_module
from .routes import PACKAGE, Routes


def _mappings(schema: Schema) -> list[Mapping]:
    return [m for s in schema.mappings for m in s.mappings]


class _Generator:
    def __init__(self, schema: Schema, header: str) -> None:
        self.schema = schema
        self.header = header
        self.concepts: dict[str, Concept] = {c.name: c for s in schema.mappings for c in s.concepts}
        self.endpoints: dict[str, Endpoint] = {e.name: e for s in schema.mappings for e in s.endpoints}
        self.edges: list[Edge] = []
        self.files: dict[str, str] = {}

    def concepts_module(self) -> None:
        self.files[f"{PACKAGE}/_concepts.py"] = concepts_module(self.concepts, self.header)

    def mapping_module(self, mapping: Mapping) -> None:
        module, text, edges = mapping_module(self.schema, self.header, mapping, self.concepts, self.endpoints)
        self.files[f"{PACKAGE}/{module}.py"] = text
        self.edges += edges

    def pair_modules(self) -> Routes:
        routes = Routes(self.schema, self.header, self.endpoints, self.edges)
        self.files.update(routes.pair_modules())
        return routes

    def init_module(self, registry: Routes) -> None:
        self.files[f"{PACKAGE}/__init__.py"] = registry.init_module()

    def render(self) -> dict[str, str]:
        self.files.update(
            copied(f"{PACKAGE}/_runtime.py", f"{PACKAGE}/_cells.py", f"{PACKAGE}/_ardupilot.py", f"{PACKAGE}/_state.py")
        )
        self.concepts_module()
        for mapping in _mappings(self.schema):
            self.mapping_module(mapping)
        registry = self.pair_modules()
        self.init_module(registry)
        return self.files


class _Converters:
    def contribute(self, msg: Message, ctx: ModuleContext, view: ClassView) -> Contribution:
        return Contribution()

    def runtime_files(self, schema: Schema, header: str) -> dict[str, str]:
        if not any(s.mappings for s in schema.mappings):
            return {}
        return _Generator(schema, header).render()


EXTENSION = _Converters()

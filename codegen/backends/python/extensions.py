"""Extension point of the Python backend: codecs and validators add code to generated classes.

Each extension sees one message at a time (with its module context and class view) and returns a
:class:`Contribution`; it may also add whole runtime modules to the package (shared helpers such as
a bit-stream reader), which must import from the standard library only.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

from ...ir import Message, Schema
from .module_context import ModuleContext
from .views import ClassView


@dataclass(frozen=True)
class Contribution:
    class_body: str = ""  # methods / class attributes, already indented by 4 spaces
    module_code: tuple[str, ...] = ()  # top-level definitions placed before the classes (deduplicated)
    imports: tuple[str, ...] = ()  # import lines for the module (deduplicated, sorted)


class Extension(Protocol):
    def contribute(self, msg: Message, ctx: ModuleContext, view: ClassView) -> Contribution: ...

    def runtime_files(self, schema: Schema, header: str) -> dict[str, str]: ...

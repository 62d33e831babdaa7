"""Names across the generated package while one module is rendered: where each class lives, the
lazy factories a module needs for classes of other modules, and its module-level private names."""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import BattgenError
from ...ir import CompositeType, Field, Schema
from . import naming


@dataclass(frozen=True)
class ClassRef:
    module: str  # dotted, relative to the generated package root
    name: str


class ModuleContext:
    """Resolves names across the generated package for one module being rendered."""

    def __init__(self, schema: Schema, module: str) -> None:
        self.schema = schema
        self.module = module
        self.classes = {
            m.qualified_name: ClassRef(naming.module_path(m), naming.class_name(m)) for m in schema.messages
        }
        self.factories: dict[str, str] = {}  # factory function name -> its source
        self.referenced: set[str] = set()  # other modules named in annotations
        self.names: dict[object, str] = {}  # what a module-level name holds -> the name
        self.module_classes = frozenset(ref.name for ref in self.classes.values() if ref.module == module)
        self.taken: set[str] = set(self.module_classes)

    def private_name(self, wanted: str, what: object) -> str:
        """A module-level name for ``what`` (the same one on every request), ``wanted`` unless taken."""
        name = self.names.get(what)
        if name is None:
            name, n = wanted, 1
            while name in self.taken:
                n += 1
                name = f"{wanted}_{n}"
            self.taken.add(name)
            self.names[what] = name
        return name

    def constant(self, owner: str, role: str) -> str:
        """The name of a module-level constant of class ``owner``: ``_BATTERY_STATUS_COLUMNS``."""
        return self.private_name(f"_{naming.upper_snake(owner)}_{role}", ("constant", owner, role))

    def composite(self, t: CompositeType, where: Field) -> ClassRef:
        ref = self.classes.get(t.name)
        if ref is None:
            loc = where.location
            raise BattgenError(f"{loc}: field {where.name!r} refers to {t.name}, which is not defined")
        return ref

    def factory(self, ref: ClassRef) -> str:
        """Name of a function returning the class ``ref`` lazily (modules may refer to each other)."""
        fname = self.private_name(f"_{naming.lower_snake(ref.name)}_class", ("class", ref))
        if fname not in self.factories:
            if ref.module == self.module:
                body = f"    return {ref.name}"
            else:
                body = f"    from {self.relative(ref.module)} import {ref.name} as cls\n\n    return cls"
            # cached: the import statement runs once, not on every decode or from_dict
            self.factories[fname] = f"@_functools.cache\ndef {fname}() -> type[{self.annotation_name(ref)}]:\n{body}"
        return fname

    def annotation_name(self, ref: ClassRef) -> str:
        if ref.module == self.module:
            return ref.name
        self.referenced.add(ref.module)
        return f"_{ref.module.replace('.', '_')}.{ref.name}"

    def type_imports(self) -> list[str]:
        """Imports under TYPE_CHECKING for annotations naming classes of other modules."""
        modules = sorted(self.referenced)
        return [
            f"from {self.relative(m.rsplit('.', 1)[0]) if '.' in m else self.root()} import "
            f"{m.rsplit('.', 1)[-1]} as _{m.replace('.', '_')}"
            for m in modules
        ]

    def root(self) -> str:
        return "." * self.depth()

    def depth(self) -> int:
        return self.module.count(".") + (2 if self.is_package() else 1)

    def is_package(self) -> bool:
        return any(other.startswith(self.module + ".") for other in {r.module for r in self.classes.values()})

    def relative(self, module: str) -> str:
        return self.root() + module

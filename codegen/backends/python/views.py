"""Template-ready views of IR messages: every string here is valid Python source, built only
through :mod:`.literals` and :mod:`.naming`, so templates just lay lines out."""

from __future__ import annotations

from dataclasses import dataclass, field

from ...errors import BattgenError
from ...ir import (
    ArrayType,
    CompositeType,
    EnumDef,
    EnumKind,
    Field,
    FieldType,
    Message,
    PrimitiveKind,
    PrimitiveType,
    Schema,
    StringType,
)
from . import naming
from .literals import docstring, prose_literal, py_literal


@dataclass(frozen=True)
class ClassRef:
    module: str  # dotted, relative to the generated package root
    name: str


@dataclass
class FieldView:
    ident: str
    annotation: str
    default: str  # "default=..." or "default_factory=..."
    meta: str  # a call building the field's metadata mapping
    to_dict: str  # statement(s) adding the value to `out`
    from_dict: str  # statement(s) reading the value from `data` into `obj`
    source_name: str
    pattern_literal: str = ""


@dataclass
class EnumView:
    class_name: str
    base: str  # IntEnum or IntFlag
    doc: str
    members: list[tuple[str, str]]  # (name, literal)


@dataclass
class ClassView:
    name: str
    qualified_name: str
    doc: str
    constants: list[tuple[str, str, str]]  # (name, annotation, literal)
    fields: list[FieldView]
    source: str
    keys_literal: str  # frozenset of accepted source names
    pattern_literal: str  # tuple of (regex, ident) for pattern fields
    extensions: list[str] = field(default_factory=list)  # extra, already indented class-body code


def _python_scalar(t: PrimitiveType) -> str:
    if t.kind is PrimitiveKind.BOOL:
        return "bool"
    if t.kind is PrimitiveKind.FLOAT:
        return "float"
    if t.kind is PrimitiveKind.CHAR:
        return "str"
    return "int"


def _is_byte_array(t: FieldType) -> bool:
    return (
        isinstance(t, ArrayType)
        and isinstance(t.element, PrimitiveType)
        and t.element.kind is PrimitiveKind.UINT
        and t.element.bits == 8
    )


def type_text(t: FieldType) -> str:
    """The type as a schema would spell it, for metadata and docs (``float32[14]``, ``uint8[<=31]``)."""
    if isinstance(t, PrimitiveType):
        return t.name
    if isinstance(t, StringType):
        return "string" if t.capacity is None else f"char[{t.capacity}]"
    if isinstance(t, CompositeType):
        return t.name
    inner = type_text(t.element)
    if t.capacity is None:
        return f"{inner}[]"
    return f"{inner}[<={t.capacity}]" if t.dynamic else f"{inner}[{t.capacity}]"


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
        self.taken: set[str] = {ref.name for ref in self.classes.values() if ref.module == module}

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
            self.factories[fname] = f"@functools.cache\ndef {fname}() -> type[{self.annotation_name(ref)}]:\n{body}"
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


def enum_views(enums: tuple[EnumDef, ...], owner: str) -> list[EnumView]:
    views = []
    for e in enums:
        group = e.short_name
        members: list[tuple[str, str]] = []
        used: set[str] = set()
        for entry in e.entries:
            name = naming.enum_member(entry.name, group)
            while name in used:
                name += "_"
            used.add(name)
            members.append((name, py_literal(entry.value)))
        kind_doc = {
            EnumKind.VALUE: "values",
            EnumKind.BITMASK: "bit masks, combined with |",
            EnumKind.BIT_INDEX: "bit positions in a bitmask field",
        }[e.kind]
        text = (e.doc + "\n\n" if e.doc else "") + f"{e.name}: {kind_doc}."
        views.append(
            EnumView(
                class_name=owner + naming.camel(group),
                base="IntFlag" if e.kind is EnumKind.BITMASK else "IntEnum",
                doc=docstring(text, "    "),
                members=members,
            )
        )
    return views


class _FieldBuilder:
    def __init__(self, ctx: ModuleContext, f: Field, optional: bool) -> None:
        self.ctx = ctx
        self.f = f
        self.optional = optional

    def annotation(self, t: FieldType) -> str:
        if isinstance(t, PrimitiveType):
            return _python_scalar(t)
        if isinstance(t, StringType):
            return "str"
        if isinstance(t, CompositeType):
            return self.ctx.annotation_name(self.ctx.composite(t, self.f))
        if _is_byte_array(t):
            return "bytes"
        return f"list[{self.annotation(t.element)}]"

    def zero(self, t: FieldType) -> str:
        """Source for a fresh default value of type ``t``."""
        if isinstance(t, PrimitiveType):
            return {"bool": "False", "float": "0.0", "str": "''", "int": "0"}[_python_scalar(t)]
        if isinstance(t, StringType):
            return "''"
        if isinstance(t, CompositeType):
            return self.ctx.factory(self.ctx.composite(t, self.f)) + "()()"
        if _is_byte_array(t):
            return f"bytes({t.capacity})" if not t.dynamic and t.capacity else "b''"
        if t.dynamic or not t.capacity:
            return "[]"
        element = self.zero(t.element)
        if isinstance(t.element, PrimitiveType | StringType):
            return f"[{element}] * {t.capacity}"
        return f"[{element} for _ in range({t.capacity})]"

    def default(self) -> str:
        f, t = self.f, self.f.type
        if f.pattern is not None:
            return "default_factory=dict"
        if self.optional:
            return "default=None"
        sentinel = f.invalid
        if sentinel is not None and isinstance(t, PrimitiveType) and not sentinel.per_element:
            return f"default={py_literal(_typed(sentinel.value, t))}"
        if sentinel is not None and isinstance(t, ArrayType) and isinstance(t.element, PrimitiveType):
            if not t.dynamic and t.capacity:
                value = py_literal(_typed(sentinel.value, t.element))
                if _is_byte_array(t):
                    return f"default_factory=lambda: bytes([{value}]) * {t.capacity}"
                return f"default_factory=lambda: [{value}] * {t.capacity}"
        if f.const is not None and isinstance(t, StringType | PrimitiveType):
            return f"default={py_literal(f.const)}"
        if f.default is not None and isinstance(t, PrimitiveType | StringType):
            return f"default={py_literal(f.default)}"
        zero = self.zero(t)
        if isinstance(t, PrimitiveType | StringType):
            return f"default={zero}"
        if zero == "b''":
            return f"default={zero}"
        if zero == "[]":
            return "default_factory=list"
        return f"default_factory=lambda: {zero}"

    def export(self, t: FieldType, expr: str) -> str:
        """Source turning attribute value ``expr`` into plain JSON-style data."""
        if isinstance(t, PrimitiveType | StringType):
            return expr
        if isinstance(t, CompositeType):
            return f"{expr}.to_dict()"
        if _is_byte_array(t):
            return f"list({expr})"
        inner = self.export(t.element, "v")
        return f"list({expr})" if inner == "v" else f"[{inner} for v in {expr}]"

    def importer(self, t: FieldType, expr: str, path: str) -> str:
        """Source reading plain data ``expr`` into a value of type ``t`` (path names it in errors)."""
        if isinstance(t, PrimitiveType):
            return f"_m.as_{_python_scalar(t)}({expr}, {path})"
        if isinstance(t, StringType):
            return f"_m.as_str({expr}, {path})"
        if isinstance(t, CompositeType):
            ref = self.ctx.composite(t, self.f)
            return f"_m.as_object({expr}, {path}, {self.ctx.factory(ref)}())"
        capacity = py_literal(t.capacity)
        fixed = py_literal(not t.dynamic)
        if _is_byte_array(t):
            return f"_m.as_bytes({expr}, {path}, {capacity}, {fixed})"
        inner = self.importer(t.element, "item", "p")
        return f"_m.as_list({expr}, {path}, {capacity}, {fixed}, lambda item, p: {inner})"


def _typed(value: int | float, t: PrimitiveType) -> int | float | bool:
    if t.kind is PrimitiveKind.FLOAT:
        return float(value)
    if t.kind is PrimitiveKind.BOOL:
        return bool(value)
    return int(value)


def _sentinel_literal(f: Field) -> str:
    assert f.invalid is not None
    t = f.type
    while isinstance(t, ArrayType):
        t = t.element
    value = _typed(f.invalid.value, t) if isinstance(t, PrimitiveType) else f.invalid.value
    return py_literal(value)


def _meta(f: Field) -> str:
    args = [f"name={py_literal(f.name)}", f"type={py_literal(type_text(f.type))}"]
    if f.unit is not None:
        args.append(f"unit={py_literal(f.unit.symbol)}")
        args.append(f"quantity={py_literal(f.unit.quantity)}")
        if f.unit.scale != 1.0 or f.unit.offset != 0.0:
            args.append(f"scale={py_literal(f.unit.scale)}")
            args.append(f"offset={py_literal(f.unit.offset)}")
    if f.range is not None:
        args.append(f"minimum={py_literal(f.range.minimum)}")
        args.append(f"maximum={py_literal(f.range.maximum)}")
    if f.invalid is not None:
        args.append(f"invalid={_sentinel_literal(f)}")
        args.append(f"invalid_text={py_literal(f.invalid.text)}")
        if f.invalid.per_element:
            args.append("per_element=True")
    if f.enums:
        args.append(f"enums={py_literal(f.enums)}")
    if f.extension:
        args.append("extension=True")
    if f.pattern is not None:
        args.append(f"pattern={py_literal(f.pattern)}")
    if f.doc:
        args.append(f"doc={prose_literal(f.doc)}")
    return "_m.meta(" + ", ".join(args) + ")"


def class_view(ctx: ModuleContext, msg: Message) -> ClassView:
    cls = naming.class_name(msg)
    optional_props = msg.devicetree is not None
    fields: list[FieldView] = []
    idents: set[str] = set(naming.RESERVED_MEMBERS)
    patterns: list[str] = []
    keys: list[str] = []
    for f in msg.fields:
        if f.is_padding:
            continue
        ident = naming.field_identifier(f.name, f.pattern)
        while ident in idents:
            ident += "_"
        idents.add(ident)
        optional = optional_props and not f.required and f.pattern is None
        b = _FieldBuilder(ctx, f, optional)
        annotation = b.annotation(f.type)
        key = py_literal(f.name)
        if f.pattern is not None:
            annotation = f"dict[str, {annotation}]"
            patterns.append(f"({py_literal(f.pattern)}, {py_literal(ident)})")
            export = b.export(f.type, "v")
            to_dict = f"out.update({{k: {export} for k, v in self.{ident}.items()}})"
            from_dict = ""
        else:
            keys.append(f.name)
            value = b.export(f.type, f"self.{ident}")
            if optional:
                annotation = f"{annotation} | None"
                to_dict = f"if self.{ident} is not None:\n    out[{key}] = {value}"
            else:
                to_dict = f"out[{key}] = {value}"
            reader = b.importer(f.type, f"data[{key}]", key)
            from_dict = f"if {key} in data:\n    obj.{ident} = {reader}"
        fields.append(FieldView(ident, annotation, b.default(), _meta(f), to_dict, from_dict, f.name))
        if f.pattern is not None:
            reader = b.importer(f.type, "value", "key")
            fields[-1].from_dict = f"obj.{ident}[key] = {reader}"
            fields[-1].pattern_literal = py_literal(f.pattern)

    constants: list[tuple[str, str, str]] = []
    for c in msg.constants:
        name = naming.identifier(c.name)
        while name in idents:
            name += "_"
        idents.add(name)
        if isinstance(c.type, PrimitiveType):
            literal = py_literal(_typed(c.value, c.type) if isinstance(c.value, int | float) else c.value)
            annotation = _python_scalar(c.type)
        else:
            literal, annotation = py_literal(str(c.value)), "str"
        constants.append((name, annotation, literal))

    src = msg.location
    doc_text = msg.doc.strip() or msg.qualified_name
    doc_text += f"\n\nSchema: {msg.qualified_name} ({msg.format.value}, {src.file}:{src.line})."
    return ClassView(
        name=cls,
        qualified_name=py_literal(msg.qualified_name),
        doc=docstring(doc_text, "    "),
        constants=constants,
        fields=fields,
        source=f"{src.file}",
        keys_literal="frozenset({" + ", ".join(py_literal(k) for k in keys) + "})" if keys else "frozenset()",
        pattern_literal="(" + ", ".join(patterns) + ",)" if patterns else "()",
    )

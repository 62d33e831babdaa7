"""The Python source of one field of a generated class: its annotation, default, metadata, and
the statements that turn it into plain data and back (``to_dict`` / ``from_dict``)."""

from __future__ import annotations

from ...ir import ArrayType, CompositeType, Field, FieldType, PrimitiveKind, PrimitiveType, StringType
from .literals import py_literal, text_literal
from .module_context import ModuleContext


def python_scalar(t: PrimitiveType) -> str:
    if t.kind is PrimitiveKind.BOOL:
        return "bool"
    if t.kind is PrimitiveKind.FLOAT:
        return "float"
    if t.kind is PrimitiveKind.CHAR:
        return "str"
    return "int"


def is_byte_array(t: FieldType) -> bool:
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


class FieldBuilder:
    def __init__(self, ctx: ModuleContext, f: Field, optional: bool) -> None:
        self.ctx = ctx
        self.f = f
        self.optional = optional

    def annotation(self, t: FieldType) -> str:
        if isinstance(t, PrimitiveType):
            return python_scalar(t)
        if isinstance(t, StringType):
            return "str"
        if isinstance(t, CompositeType):
            return self.ctx.annotation_name(self.ctx.composite(t, self.f))
        if is_byte_array(t):
            return "bytes"
        return f"list[{self.annotation(t.element)}]"

    def zero(self, t: FieldType) -> str:
        """Source for a fresh default value of type ``t``."""
        if isinstance(t, PrimitiveType):
            return {"bool": "False", "float": "0.0", "str": '""', "int": "0"}[python_scalar(t)]
        if isinstance(t, StringType):
            return '""'
        if isinstance(t, CompositeType):
            return self.ctx.factory(self.ctx.composite(t, self.f)) + "()()"
        if is_byte_array(t):
            return f"bytes({t.capacity})" if not t.dynamic and t.capacity else 'b""'
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
            return f"default={py_literal(typed(sentinel.value, t))}"
        if sentinel is not None and isinstance(t, ArrayType) and isinstance(t.element, PrimitiveType):
            if not t.dynamic and t.capacity and sentinel.elements:  # marked positions hold their marker
                element = t.element
                fill = [typed(sentinel.marker_at(i) or 0, element) for i in range(t.capacity)]
                if is_byte_array(t):
                    return f"default_factory=lambda: bytes({py_literal(fill)})"
                return f"default_factory=lambda: {py_literal(fill)}"
            if not t.dynamic and t.capacity:
                value = py_literal(typed(sentinel.value, t.element))
                if is_byte_array(t):
                    return f"default_factory=lambda: bytes([{value}]) * {t.capacity}"
                return f"default_factory=lambda: [{value}] * {t.capacity}"
        if f.const is not None and isinstance(t, StringType | PrimitiveType):
            return f"default={py_literal(f.const)}"
        if f.default is not None and isinstance(t, PrimitiveType | StringType):
            return f"default={py_literal(f.default)}"
        zero = self.zero(t)
        if isinstance(t, PrimitiveType | StringType):
            return f"default={zero}"
        if zero == 'b""':
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
        if is_byte_array(t):
            return f"list({expr})"
        inner = self.export(t.element, "v")
        return f"list({expr})" if inner == "v" else f"[{inner} for v in {expr}]"

    def importer(self, t: FieldType, expr: str, path: str) -> str:
        """Source reading plain data ``expr`` into a value of type ``t`` (path names it in errors)."""
        if isinstance(t, PrimitiveType):
            return f"_m.as_{python_scalar(t)}({expr}, {path})"
        if isinstance(t, StringType):
            return f"_m.as_str({expr}, {path})"
        if isinstance(t, CompositeType):
            ref = self.ctx.composite(t, self.f)
            return f"_m.as_object({expr}, {path}, {self.ctx.factory(ref)}())"
        capacity = py_literal(t.capacity)
        fixed = py_literal(not t.dynamic)
        if is_byte_array(t):
            return f"_m.as_bytes({expr}, {path}, {capacity}, {fixed})"
        inner = self.importer(t.element, "item", "p")
        return f"_m.as_list({expr}, {path}, {capacity}, {fixed}, lambda item, p: {inner})"

    def fast_importer(self, t: FieldType, var: str, path: str) -> str:
        """Like :meth:`importer` on the plain value in variable ``var``, with the IR's type deciding the
        test: a value already of the attribute's exact Python type (what JSON gives) is taken as it is,
        anything else goes to the runtime reader, which converts it or raises DataError naming ``path``."""
        if isinstance(t, PrimitiveType | StringType):
            scalar = "str" if isinstance(t, StringType) else python_scalar(t)
            return f"{var} if {var}.__class__ is {scalar} else _m.as_{scalar}({var}, {path})"
        if isinstance(t, ArrayType) and isinstance(t.element, PrimitiveType) and not is_byte_array(t):
            scalar = python_scalar(t.element)
            capacity, fixed = py_literal(t.capacity), py_literal(not t.dynamic)
            return f"_m.as_typed_list({var}, {path}, {capacity}, {fixed}, {scalar}, _m.as_{scalar})"
        return self.importer(t, var, path)


def typed(value: int | float, t: PrimitiveType) -> int | float | bool:
    if t.kind is PrimitiveKind.FLOAT:
        return float(value)
    if t.kind is PrimitiveKind.BOOL:
        return bool(value)
    return int(value)


def sentinel_literal(f: Field) -> str:
    assert f.invalid is not None
    t = f.type
    while isinstance(t, ArrayType):
        t = t.element
    value = typed(f.invalid.value, t) if isinstance(t, PrimitiveType) else f.invalid.value
    return py_literal(value)


def meta(f: Field) -> str:
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
        args.append(f"invalid={sentinel_literal(f)}")
        args.append(f"invalid_text={py_literal(f.invalid.text)}")
        if f.invalid.per_element:
            args.append("per_element=True")
        if f.invalid.first_decides:
            args.append("first_decides=True")
    if f.enums:
        args.append(f"enums={py_literal(f.enums)}")
    if f.extension:
        args.append("extension=True")
    if f.pattern is not None:
        args.append(f"pattern={py_literal(f.pattern)}")
    if f.doc:
        args.append(f"doc={text_literal(f.doc)}")
    return "_m.meta(" + ", ".join(args) + ")"

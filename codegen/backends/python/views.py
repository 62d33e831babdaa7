"""Template-ready views of IR messages: every string here is valid Python source, built only
through :mod:`.literals` and :mod:`.naming`, so templates just lay lines out."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from ...ir import (
    EnumDef,
    EnumKind,
    Message,
    PrimitiveType,
)
from . import naming
from .field_source import FieldBuilder, meta, python_scalar, typed
from .literals import docstring, py_literal
from .module_context import ModuleContext

__all__ = ["ClassView", "EnumView", "FieldView", "ModuleContext", "class_view", "enum_views"]


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
    keys_name: str  # the module-level constant holding it (built once, not on every from_dict)
    pattern_literal: str  # tuple of (regex, ident) for pattern fields
    extensions: list[str] = field(default_factory=list)  # extra, already indented class-body code
    union_table: str = ""  # a DroneCAN union's module-level _dc.Union (from_dict lets it pick the branch)
    # a record naming every field (as to_dict writes one): its values in one look-up, the class built from them
    whole_getter: str = ""  # module-level operator.itemgetter of every field's name, in field order
    whole_keys: str = ""  # the itemgetter's arguments
    whole_count: int = 0  # how many
    whole_fetch: str = ""  # the getter's call, assigning every value to its local
    whole_from_dict: str = ""  # the statement building the instance from those locals (unindented)


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
                class_name=naming.class_identifier(owner + naming.camel(group)),
                base="IntFlag" if e.kind is EnumKind.BITMASK else "IntEnum",
                doc=docstring(text, "    "),
                members=members,
            )
        )
    return views


def class_view(ctx: ModuleContext, msg: Message) -> ClassView:
    cls = naming.class_name(msg)
    optional_props = msg.devicetree is not None
    # a DSDL union: every branch is None but the one held (see runtime/_dronecan.Union)
    union = msg.is_union
    fields: list[FieldView] = []
    whole: list[str] = []  # each field's reader of the local holding its value, for the whole-record path
    names = naming.member_names(msg, ctx.module_classes)
    patterns: list[str] = []
    keys: list[str] = []
    for f in msg.fields:
        if f.is_padding:
            continue
        ident = names[("field", f.name)]
        optional = (optional_props and not f.required and f.pattern is None) or union
        b = FieldBuilder(ctx, f, optional)
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
            reader = b.fast_importer(f.type, "x", key)
            from_dict = f"if {key} in data:\n    x = data[{key}]\n    obj.{ident} = {reader}"
            whole.append(b.fast_importer(f.type, f"v{len(whole)}", key))
        fields.append(FieldView(ident, annotation, b.default(), meta(f), to_dict, from_dict, f.name))
        if f.pattern is not None:
            reader = b.importer(f.type, "value", "key")
            fields[-1].from_dict = f"obj.{ident}[key] = {reader}"
            fields[-1].pattern_literal = py_literal(f.pattern)

    constants: list[tuple[str, str, str]] = []
    # an enum's entries are its IntEnum/IntFlag class's members alone (BatteryInfoStatusFlag.IN_USE), not
    # class constants as well; a constant outside every enum (FAULT_COUNT) stays a class attribute
    entries = {entry.name for e in msg.enums for entry in e.entries}
    for c in msg.constants:
        if c.name in entries:
            continue
        name = names[("constant", c.name)]
        if isinstance(c.type, PrimitiveType):
            literal = py_literal(typed(c.value, c.type) if isinstance(c.value, int | float) else c.value)
            annotation = python_scalar(c.type)
        else:
            literal, annotation = py_literal(str(c.value)), "str"
        constants.append((name, annotation, literal))

    view_whole = _whole_record(ctx, cls, keys, whole) if not union and not patterns and len(whole) > 1 else None
    if union:
        keys.append("union_field")
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
        keys_name=ctx.constant(cls, "KEYS"),
        pattern_literal="(" + ", ".join(patterns) + ",)" if patterns else "()",
        union_table=ctx.constant(cls, "UNION") if union else "",
        **(view_whole or {}),
    )


def _whole_record(ctx: ModuleContext, cls: str, keys: list[str], readers: list[str]) -> dict[str, Any]:
    """The path of ``from_dict`` for a plain dict naming every field: one ``itemgetter`` call fetches the
    values into locals ``v0``.. (no per-field membership test, no default set and then overwritten), each
    taken as it is when of the attribute's type, and the class is called with them in field order."""
    targets = ", ".join(f"v{i}" for i in range(len(readers)))
    getter = ctx.constant(cls, "VALUES")
    return {
        "whole_getter": getter,
        "whole_keys": ", ".join(py_literal(k) for k in keys),
        "whole_count": len(keys),
        "whole_fetch": f"{targets} = {getter}(data)",
        "whole_from_dict": "return cls(\n" + "".join(f"    {r},\n" for r in readers) + ")",
    }

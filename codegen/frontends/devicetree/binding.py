"""One dt-schema binding (a loaded YAML document) -> IR Messages: the binding, and its sub-nodes.

One binding (``$id: http://devicetree.org/schemas/power/supply/battery.yaml#``) becomes one
Message ``devicetree.power.supply.battery``; each entry of ``properties`` / ``patternProperties``
becomes a Field (typed by :mod:`.refs` and :mod:`.shape`). Sub-nodes described inline, and local
definitions they refer to, become messages of their own, named below the parent. Schema keys the
IR has no place for are kept verbatim as ``schema.<key>`` annotations.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any
from urllib.parse import urlparse

from ...errors import SchemaError
from ...ir import CompositeType, DevicetreeInfo, Field, Location, Message, SourceFormat
from ...text.yaml_lines import YList, YMap
from .data import DtData
from .refs import RefContext, Resolved, pointer, resolve
from .shape import UNKNOWN_TYPE, as_text, ir_type, shape_of, values_of, with_columns

PREFIX = "devicetree"
# keys of a property schema the IR holds; the rest are kept verbatim in annotations
_UNDERSTOOD = frozenset(
    {"$ref", "description", "type", "const", "enum", "items", "minItems", "maxItems", "minimum", "maximum",
     "exclusiveMinimum", "exclusiveMaximum", "default", "properties", "patternProperties",
     "additionalProperties", "unevaluatedProperties", "required", "title", "maintainers", "$id", "$schema"}
)  # fmt: skip


def qualified_name(schema_id: str) -> str | None:
    """``http://devicetree.org/schemas/power/supply/battery.yaml#`` -> ``devicetree.power.supply.battery``."""
    path = urlparse(schema_id).path if "://" in schema_id else schema_id
    path = path.split("#", 1)[0]
    if "/schemas/" in f"/{path.lstrip('/')}":
        path = f"/{path.lstrip('/')}".split("/schemas/", 1)[1]
    path = path.strip("/")
    if not path.endswith(".yaml") or len(path) <= len(".yaml"):
        return None
    return ".".join([PREFIX, *path[: -len(".yaml")].split("/")])


@dataclass
class _File:
    ctx: RefContext
    qualified: str
    messages: list[Message] = field(default_factory=list)
    local_nodes: dict[str, str] = field(default_factory=dict)  # local "#/..." pointer -> message name
    taken: set[str] = field(default_factory=set)

    @property
    def display(self) -> str:
        return self.ctx.display

    def fail(self, line: int, what: str) -> SchemaError:
        return SchemaError(self.display, line, what)

    def child_name(self, parent: str, prop: str) -> str:
        stem = re.sub(r"[^A-Za-z0-9_,+-]+", "_", prop.strip("^$")).strip("_") or "node"
        name, n = f"{parent}.{stem}", 2
        while name in self.taken:
            name, n = f"{parent}.{stem}_{n}", n + 1
        self.taken.add(name)
        return name


def _text(value: Any) -> str:
    return value.strip() if isinstance(value, str) else ""


def _strings(node: YMap, key: str, f: _File) -> tuple[str, ...]:
    value = node.get(key, YList())
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise f.fail(node.line_of(key), f"expected {key!r} to be a list of strings")
    return tuple(value)


def _compatibles(schema: Any) -> tuple[str, ...]:
    """Every string a ``compatible`` schema allows (const / enum values), in order, once each."""
    found: list[str] = []

    def walk(node: Any) -> None:
        if isinstance(node, YMap):
            for key, value in node.items():
                if key == "const" and isinstance(value, str):
                    found.append(value)
                elif key == "enum" and isinstance(value, list):
                    found.extend(v for v in value if isinstance(v, str))
                elif key != "description":
                    walk(value)
        elif isinstance(node, list):
            for item in node:
                walk(item)

    walk(schema)
    return tuple(dict.fromkeys(found))


def _choices(schema: YMap) -> tuple[str | int | None, tuple[str | int, ...], tuple[tuple[str, str], ...], bool]:
    """const, enum choices, per-choice descriptions (``oneOf: [{const, description}]``), and
    whether a oneOf/anyOf was nothing but such consts (so it needs no verbatim copy)."""
    # old-style bindings put the constraint beside the type: allOf: [{$ref: ...}, {enum: [...]}]
    subs = schema.get("allOf")
    parts = [schema, *(s for s in subs if isinstance(s, YMap))] if isinstance(subs, list) else [schema]
    consts = [p["const"] for p in parts if isinstance(p.get("const"), str | int) and not isinstance(p["const"], bool)]
    const = consts[0] if consts else None
    choices: list[str | int] = [
        v for p in parts if isinstance(p.get("enum"), list) for v in p["enum"] if isinstance(v, str | int)
    ]
    notes: list[tuple[str, str]] = []
    consumed = False
    for key in ("oneOf", "anyOf"):
        alts = schema.get(key)
        if (
            isinstance(alts, list)
            and alts
            and all(isinstance(a, YMap) and a.keys() <= {"const", "description"} for a in alts)
        ):
            consumed = True
            for alt in alts:
                if isinstance(alt["const"], str | int) and not isinstance(alt["const"], bool):
                    choices.append(alt["const"])
                    if _text(alt.get("description")):
                        notes.append((f"choice.{alt['const']}", " ".join(alt["description"].split())))
    return const, tuple(dict.fromkeys(choices)), tuple(notes), consumed


def _leftovers(schema: YMap, consumed_choices: bool) -> list[tuple[str, str]]:
    out: list[tuple[str, str]] = []
    for key in sorted(schema.keys(), key=str):
        if key in _UNDERSTOOD or (consumed_choices and key in ("oneOf", "anyOf")):
            continue
        out.append((f"schema.{key}", as_text(schema[key])))
    return out


def _field(f: _File, parent: str, name: str, schema: Any, line: int, *, is_pattern: bool, required: bool) -> Field:
    data: DtData = f.ctx.data
    found: Resolved = resolve(f.ctx, name, schema, is_pattern=is_pattern)
    node = schema if isinstance(schema, YMap) else YMap()
    doc = _text(node.get("description"))
    notes: list[tuple[str, str]] = [("dt-type", found.dt_type or "unknown"), ("dt-type-source", found.source)]
    notes += [("dt-type-alternative", t) for t in found.others]
    rule = data.unit_rule(name)
    unit = rule.unit if rule is not None else None
    unit_text = rule.unit_text if rule is not None else None
    rng = None
    if found.dt_type == "node":
        ftype: Any = CompositeType(_node_message(f, parent, name, node, found, line))
    elif found.dt_type is None:
        ftype = UNKNOWN_TYPE
    else:
        td = data.types.get(found.dt_type)
        if td is None:  # a types.yaml of the schema folder that leaves out a type the frontend names
            raise SchemaError(
                f.display, line, f"expected types.yaml to define {found.dt_type!r}, the type of property {name!r}"
            )
        shape = shape_of(td, node, found.source == "unit-suffix")
        values = values_of(node, shape, f.display)
        ftype = with_columns(ir_type(td, shape), values)
        rng = values.range
        notes += values.notes
        if td.value == "phandle":
            notes.append(("dt-phandle", "a 32-bit cell naming another node"))
    const, choices, choice_notes, consumed = _choices(node)
    notes += choice_notes
    notes += _leftovers(node, consumed)
    default = node.get("default")
    return Field(
        name=name,
        type=ftype,
        location=Location(f.display, line),
        doc=doc,
        unit=unit,
        unit_text=unit_text,
        range=rng,
        pattern=name if is_pattern else None,
        required=required,
        const=const,
        choices=choices,
        default=default if isinstance(default, int | float | str) else None,
        annotations=tuple(notes),
    )


def _node_message(f: _File, parent: str, prop: str, node: YMap, found: Resolved, line: int) -> str:
    """The message a node-typed property refers to; inline and local nodes are built here."""
    if found.target is not None and not found.target.startswith("#"):
        return qualified_name(found.target) or f"{PREFIX}.unresolved"
    if found.target is not None:  # a local definition, built once even when it refers to itself
        if found.target not in f.local_nodes:
            target = pointer(f.ctx.doc, found.target[1:])
            f.local_nodes[found.target] = f.child_name(f.qualified, found.target.rsplit("/", 1)[-1])
            body = target if isinstance(target, YMap) else YMap()
            _build(f, f.local_nodes[found.target], body, f"{f.ctx.base_uri}{found.target[1:]}", line)
        return f.local_nodes[found.target]
    name = f.child_name(parent, prop)
    _build(f, name, node, f"{f.ctx.base_uri}/properties/{prop.replace('~', '~0').replace('/', '~1')}", line)
    return name


def _section(f: _File, node: YMap, key: str) -> YMap:
    value = node.get(key, YMap())
    if value is True or value is False or value is None:  # "properties: true" allows anything
        return YMap()
    if not isinstance(value, YMap):
        raise f.fail(node.line_of(key), f"expected {key!r} to be a mapping of property name to schema")
    return value


def _build(f: _File, qualified: str, node: YMap, schema_id: str, line: int) -> None:
    required = _strings(node, "required", f)
    fields: list[Field] = []
    for key, pattern in (("properties", False), ("patternProperties", True)):
        section = _section(f, node, key)
        for name, schema in section.items():
            pline = section.line_of(name)
            if not isinstance(name, str):
                raise f.fail(pline, f"expected a property name (a string), not {name!r}")
            if schema is False:  # forbidden here: not a field
                continue
            if not isinstance(schema, YMap) and schema is not True:
                raise f.fail(pline, f"expected the schema of {name!r} to be a mapping or true")
            if pattern:
                try:
                    re.compile(name)
                except re.error:
                    raise f.fail(pline, f"expected {name!r} to be a regular expression") from None
            fields.append(_field(f, qualified, name, schema, pline, is_pattern=pattern, required=name in required))
    closed = node.get("additionalProperties") is False or node.get("unevaluatedProperties") is False
    props = node.get("properties")
    compat = _compatibles(props.get("compatible")) if isinstance(props, YMap) else ()
    title = _text(node.get("title"))
    f.messages.append(
        Message(
            name=qualified.rsplit(".", 1)[-1],
            qualified_name=qualified,
            format=SourceFormat.DEVICETREE,
            location=Location(f.display, line),
            doc=_text(node.get("description")) or title,
            fields=tuple(fields),
            devicetree=DevicetreeInfo(
                schema_id=schema_id,
                title=title,
                compatible=compat,
                required=required,
                additional_properties=not closed,
                maintainers=_strings(node, "maintainers", f),
            ),
        )
    )


def binding_messages(doc: Any, display: str, data: DtData) -> list[Message]:
    if not isinstance(doc, YMap):
        raise SchemaError(display, getattr(doc, "line", 1) or 1, "expected a mapping (a dt-schema binding)")
    schema_id = doc.get("$id")
    if schema_id is None:
        raise SchemaError(display, doc.line, "expected a '$id' key (e.g. http://devicetree.org/schemas/x/y.yaml#)")
    qualified = qualified_name(schema_id) if isinstance(schema_id, str) else None
    if qualified is None:
        raise SchemaError(display, doc.line_of("$id"), f"expected $id to name a .yaml schema, not {schema_id!r}")
    f = _File(RefContext(display, doc, str(schema_id), data), qualified, taken={qualified})
    _build(f, qualified, doc, str(schema_id), doc.line_of("$id"))
    return f.messages


def is_binding(doc: Any) -> bool:
    """Whether a loaded YAML document is a binding (has an $id and properties), not some other file."""
    return isinstance(doc, YMap) and "$id" in doc and bool(doc.keys() & {"properties", "patternProperties"})

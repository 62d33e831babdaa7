"""pydsdl's types -> IR Messages: a message type is one Message, a service two (Request, Response).

Names: ``cyphal.<namespace>.<Short>_<major>_<minor>`` (nunavut's spelling of a versioned name, so the
versions of one type live side by side), a service's halves ``...<Short>_<major>_<minor>.Request`` and
``.Response``. A ``reg.drone`` type is named as its ``reg.udral`` twin; its ``CyphalInfo`` keeps the name
the file gave. Bit lengths, extents, sealing and port ids are pydsdl's.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import pydsdl

from ...ir import (
    ArrayType,
    CastMode,
    CompositeType,
    Constant,
    CyphalInfo,
    CyphalKind,
    EnumDef,
    Field,
    FieldType,
    Location,
    Message,
    PrimitiveKind,
    PrimitiveType,
    Schema,
    SchemaWarning,
    Sentinel,
    Unit,
    units,
)
from ...ir import SourceFormat as Fmt
from ...text.files import display_path
from . import semantics as sem

PREFIX = "cyphal."


def type_name(t: pydsdl.CompositeType) -> str:
    """The qualified IR name of a (non-service) composite type."""
    full = sem.canonical_name(t.full_name)
    namespace, _, short = full.rpartition(".")
    return f"{PREFIX}{namespace}.{short}_{t.version.major}_{t.version.minor}"


def build(types: Iterable[pydsdl.CompositeType], root: Path) -> Schema:
    """The Schema of the types read below ``root`` (every reference among them resolves)."""
    chosen: dict[str, pydsdl.CompositeType] = {}
    warnings: list[SchemaWarning] = []
    for t in sorted(types, key=lambda t: (t.full_name.startswith(sem.DRONE_PREFIX), str(t))):
        key = type_name(t)
        prior = chosen.get(key)
        if prior is None:
            chosen[key] = t
        elif str(prior) != str(t):  # reg.udral wins over its reg.drone twin
            where = Location(display_path(t.source_file_path, root), 0)
            warnings.append(SchemaWarning(where, "cyphal-alias", f"{t} is read as {prior}, which is also given"))
    messages: list[Message] = []
    for t in chosen.values():
        messages += _Builder(t, root).messages()
    messages.sort(key=lambda m: m.qualified_name)
    sources = tuple(sorted({display_path(t.source_file_path, root) for t in chosen.values()}))
    return Schema(messages=tuple(messages), sources=sources, warnings=tuple(warnings))


class _Builder:
    def __init__(self, t: pydsdl.CompositeType, root: Path) -> None:
        self.t = t
        self.file = display_path(t.source_file_path, root)
        text = t.source_file_path.read_text(encoding="utf-8")
        if isinstance(t, pydsdl.ServiceType):
            sections = [_inner(t.request_type).attributes, _inner(t.response_type).attributes]
        else:
            sections = [_inner(t).attributes]
        self.lines = sem.attribute_lines(text, [list(s) for s in sections])

    def messages(self) -> list[Message]:
        t = self.t
        if not isinstance(t, pydsdl.ServiceType):
            return [self._message(t, type_name(t), CyphalKind.MESSAGE, self.lines[0])]
        base = type_name(t)
        return [
            self._message(t.request_type, base + ".Request", CyphalKind.REQUEST, self.lines[0]),
            self._message(t.response_type, base + ".Response", CyphalKind.RESPONSE, self.lines[1]),
        ]

    def _message(self, part: pydsdl.CompositeType, qualified: str, kind: CyphalKind, lines: dict[str, int]) -> Message:
        t = self.t
        inner = _inner(part)
        canonical = sem.canonical_name(t.full_name)
        info = CyphalInfo(
            full_name=t.full_name,
            major=t.version.major,
            minor=t.version.minor,
            kind=kind,
            union=isinstance(inner, pydsdl.UnionType),
            sealed=not isinstance(part, pydsdl.DelimitedType),
            extent=part.extent,
            min_bitlen=inner.bit_length_set.min,
            max_bitlen=inner.bit_length_set.max,
            fixed_port_id=t.fixed_port_id,
            deprecated=t.deprecated,
            union_tag_bits=inner.tag_field_type.bit_length if isinstance(inner, pydsdl.UnionType) else 0,
            alias_of=canonical if canonical != t.full_name else None,
        )
        enum = sem.enum_of(qualified, inner, self.file, lines)
        fields = tuple(self._field(inner, f, index, lines, enum) for index, f in enumerate(inner.fields))
        constants = tuple(
            Constant(
                c.name,
                _primitive(c.data_type),
                sem.constant_value(c.value),
                c.doc,
                Location(self.file, lines.get("constant " + c.name, 0)),
            )
            for c in inner.constants
        )
        short = qualified.removeprefix(PREFIX + canonical.rpartition(".")[0] + ".")
        doc = t.doc if kind is CyphalKind.MESSAGE else "\n".join(d for d in (t.doc, part.doc) if d)
        return Message(
            name=short.replace(".", "_"),
            qualified_name=qualified,
            format=Fmt.CYPHAL,
            location=Location(self.file, lines["section"]),
            doc=doc,
            fields=fields,
            constants=constants,
            enums=(enum,) if enum is not None else (),
            cyphal=info,
        )

    def _field(
        self, owner: pydsdl.CompositeType, f: pydsdl.Field, index: int, lines: dict[str, int], enum: EnumDef | None
    ) -> Field:
        owner_name = self.t.full_name
        padding = isinstance(f, pydsdl.PaddingField)
        key = f"void {sum(isinstance(g, pydsdl.PaddingField) for g in owner.fields[:index])}" if padding else ""
        location = Location(self.file, lines.get(key or "field " + f.name, 0))
        element = f.data_type
        while isinstance(element, pydsdl.ArrayType):
            element = element.element_type
        doc = f.doc
        unit: Unit | None
        if isinstance(element, pydsdl.CompositeType):
            unit, unit_text = _carried_unit(element)
        else:
            unit, unit_text, doc = sem.field_unit(owner_name, f, doc)
        invalid = None if padding else sem.unknown_sentinel(owner, f)
        if invalid is None and sem.nan_when_unknown(owner_name, element):
            invalid = Sentinel(float("nan"), "NaN", per_element=isinstance(f.data_type, pydsdl.ArrayType))
        notes: tuple[tuple[str, str], ...] = ()
        if isinstance(element, pydsdl.UTF8Type | pydsdl.ByteType):
            notes = (("dsdl", "utf8" if isinstance(element, pydsdl.UTF8Type) else "byte"),)
        return Field(
            name="" if padding else f.name,
            type=_ir_type(f.data_type),
            location=location,
            doc=doc,
            unit=unit,
            unit_text=unit_text,
            invalid=invalid,
            enums=(enum.name,) if enum is not None and not padding else (),
            annotations=notes,
        )


def _inner(t: pydsdl.CompositeType) -> pydsdl.CompositeType:
    return t.inner_type if isinstance(t, pydsdl.DelimitedType) else t


def _carried_unit(t: pydsdl.CompositeType) -> tuple[Unit | None, str | None]:
    """The unit of a one-value ``uavcan.si`` type, which a field of that type carries."""
    inner = _inner(t)
    fields = sem.value_fields(inner)
    if (
        len(fields) != 1
        or not sem.names_units(t.full_name)
        or not sem.canonical_name(t.full_name).startswith("uavcan.si.")
    ):
        return None, None
    name = fields[0].name
    return units.lookup(name) or units.opaque(name), name


def _primitive(t: pydsdl.PrimitiveType) -> PrimitiveType:
    cast = CastMode.SATURATED if t.cast_mode is pydsdl.PrimitiveType.CastMode.SATURATED else CastMode.TRUNCATED
    if isinstance(t, pydsdl.BooleanType):
        return PrimitiveType(PrimitiveKind.BOOL, 1, cast)
    if isinstance(t, pydsdl.SignedIntegerType):
        return PrimitiveType(PrimitiveKind.INT, t.bit_length, cast)
    if isinstance(t, pydsdl.FloatType):
        return PrimitiveType(PrimitiveKind.FLOAT, t.bit_length, cast)
    return PrimitiveType(PrimitiveKind.UINT, t.bit_length, cast)  # uintN, and utf8 / byte elements


def _ir_type(t: pydsdl.SerializableType) -> FieldType:
    if isinstance(t, pydsdl.VoidType):
        return PrimitiveType(PrimitiveKind.VOID, t.bit_length)
    if isinstance(t, pydsdl.PrimitiveType):
        return _primitive(t)
    if isinstance(t, pydsdl.FixedLengthArrayType):
        return ArrayType(_ir_type(t.element_type), t.capacity, False, t.capacity)
    if isinstance(t, pydsdl.VariableLengthArrayType):
        return ArrayType(_ir_type(t.element_type), t.capacity, True)
    assert isinstance(t, pydsdl.CompositeType), t
    return CompositeType(type_name(t))

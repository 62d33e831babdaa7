"""Parsed DSDL definitions -> IR Messages: a message is one Message, a service two (Request, Response).

Signatures and bit lengths come from :mod:`.signature`; docs, units, ranges, enums and sentinels
from what comments and constant names say (:mod:`.semantics`).
"""

from __future__ import annotations

from collections.abc import Mapping

from ...errors import SchemaError
from ...ir import (
    ArrayType,
    CastMode,
    CompositeType,
    Constant,
    DronecanInfo,
    DronecanKind,
    Field,
    FieldType,
    Location,
    Message,
    PrimitiveKind,
    PrimitiveType,
    Schema,
    SourceFormat,
)
from . import semantics as sem
from .definitions import AttrT, PrimT, RefT, Section, TypeDef, VoidT
from .signature import data_type_signature, normalized_definition, section_max_bits, section_min_bits

PREFIX = "dronecan."


def build(defs: Mapping[str, TypeDef]) -> Schema:
    """The Schema of every definition loaded (each reference among them resolves)."""
    builder = _Builder(defs)
    messages: list[Message] = []
    for td in defs.values():
        messages.extend(builder.messages(td))
    messages.sort(key=lambda m: m.qualified_name)
    sources = tuple(sorted(td.file for td in defs.values()))
    return Schema(messages=tuple(messages), sources=sources)


class _Builder:
    def __init__(self, defs: Mapping[str, TypeDef]) -> None:
        self.lookup = defs.__getitem__
        self._signatures: dict[str, int] = {}  # data type signatures, computed once per type

    def messages(self, td: TypeDef) -> list[Message]:
        signature = data_type_signature(td, self.lookup, self._signatures)
        normalized = normalized_definition(td)
        if td.response is None:
            halves = [(PREFIX + td.full_name, td.short_name, DronecanKind.MESSAGE, td.request)]
        else:
            base = PREFIX + td.full_name
            halves = [
                (f"{base}.Request", f"{td.short_name}Request", DronecanKind.REQUEST, td.request),
                (f"{base}.Response", f"{td.short_name}Response", DronecanKind.RESPONSE, td.response),
            ]
        out = []
        for qualified, name, kind, section in halves:
            info = DronecanInfo(
                full_name=td.full_name,
                data_type_id=td.default_id,
                signature=signature,
                kind=kind,
                union=section.union,
                min_bitlen=section_min_bits(section, self.lookup),
                max_bitlen=section_max_bits(section, self.lookup),
                min_bitlen_tao=section_min_bits(section, self.lookup),
                max_bitlen_tao=section_max_bits(section, self.lookup, tao=True),
                normalized_definition=normalized,
            )
            out.append(self._message(td, qualified, name, section, info))
        return out

    def _message(self, td: TypeDef, qualified: str, name: str, section: Section, info: DronecanInfo) -> Message:
        enums, links = sem.group_enums(qualified, section.constants, section.fields, td.file)
        invalid = sem.sentinels(section.constants, section.fields)
        fields = []
        for f in section.fields:
            unit_text, value_range, rest = sem.split_tag(f.trailing)
            is_float = isinstance(f.type, PrimT) and f.type.kind == "float"
            tagged, problem, rest = sem.split_invalid(rest, is_float)
            if problem:
                raise SchemaError(td.file, f.line, problem)
            fields.append(
                Field(
                    name=f.name if f.name and not isinstance(f.type, VoidT) else "",
                    type=_ir_type(f.type),
                    location=Location(td.file, f.line),
                    doc=sem.join_doc(f.above, rest),
                    unit=sem.resolve_unit(unit_text) if unit_text else None,
                    unit_text=unit_text,
                    range=value_range,
                    invalid=invalid.get(f.name or "") or tagged,
                    enums=links.get(f.name or "", ()),
                )
            )
        constants = tuple(
            Constant(
                c.name, _ir_primitive(c.type), c.value, sem.join_doc(c.above, c.trailing), Location(td.file, c.line)
            )
            for c in section.constants
        )
        return Message(
            name=name,
            qualified_name=qualified,
            format=SourceFormat.DRONECAN,
            location=Location(td.file, section.line),
            doc=td.doc,
            fields=tuple(fields),
            constants=constants,
            enums=enums,
            dronecan=info,
        )


_KINDS = {
    "bool": PrimitiveKind.BOOL,
    "uint": PrimitiveKind.UINT,
    "int": PrimitiveKind.INT,
    "float": PrimitiveKind.FLOAT,
}


def _ir_primitive(t: PrimT) -> PrimitiveType:
    return PrimitiveType(_KINDS[t.kind], t.bits, CastMode(t.cast))


def _ir_type(t: AttrT) -> FieldType:
    if isinstance(t, PrimT):
        return _ir_primitive(t)
    if isinstance(t, VoidT):
        return PrimitiveType(PrimitiveKind.VOID, t.bits)
    if isinstance(t, RefT):
        return CompositeType(PREFIX + t.full_name)
    element = _ir_type(t.element)
    return ArrayType(element, t.size, t.dynamic, 0 if t.dynamic else t.size)

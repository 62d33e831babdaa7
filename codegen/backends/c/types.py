"""The C spelling of IR field types (the language support, kept apart from the file layout)."""

from __future__ import annotations

import re

from ...ir import ArrayType, CompositeType, FieldType, PrimitiveKind, PrimitiveType, StringType


def ident(name: str) -> str:
    """A C identifier for a source name (``voltage-min`` -> ``voltage_min``)."""
    out = re.sub(r"[^0-9A-Za-z_]", "_", name)
    return "_" + out if out[:1].isdigit() else out


def type_name(qualified: str) -> str:
    """``dronecan.uavcan.equipment.power.BatteryInfo`` -> ``battgen_dronecan_uavcan_equipment_power_BatteryInfo``."""
    return "battgen_" + ident(qualified.replace(".", "_"))


def scalar(t: PrimitiveType) -> str:
    """The C type holding a value of ``t`` (DSDL's odd widths widen to the next standard one)."""
    if t.kind is PrimitiveKind.BOOL:
        return "bool"
    if t.kind is PrimitiveKind.CHAR:
        return "char"
    if t.kind is PrimitiveKind.FLOAT:
        return "double" if t.bits > 32 else "float"
    width = next(w for w in (8, 16, 32, 64) if t.bits <= w)
    return ("uint" if t.kind is PrimitiveKind.UINT else "int") + f"{width}_t"


def member(t: FieldType, name: str) -> list[str]:
    """Member declarations for one field (a dynamic array also gets its length)."""
    if isinstance(t, PrimitiveType):
        return [f"{scalar(t)} {name};"]
    if isinstance(t, CompositeType):
        return [f"{type_name(t.name)} {name};"]
    if isinstance(t, StringType):
        return [f"char {name}[{(t.capacity or 0) + 1}];"]
    assert isinstance(t, ArrayType)
    inner = member(t.element, name)
    decl = inner[0][:-1] + f"[{t.capacity or 1}];"
    if t.dynamic:
        return [f"uint16_t {name}_len;", decl]
    return [decl]

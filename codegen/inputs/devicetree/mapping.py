"""From devicetree nodes to the plain dict a generated devicetree model's ``from_dict`` accepts.

Values stay in their schema units (the raw cells). The IR field type says how to cut the bytes:
element width and signedness, and for matrices the row length. Rows are cut as dtschema cuts a
.dtb (the blob keeps no ``<...>`` grouping): the fewest rows whose length the matrix's
dimensions allow, else the fixed row length, else one row -- so .dts and .dtb input give the
same dict.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from typing import Any

from ...ir import ArrayType, Field, Message, PrimitiveKind, PrimitiveType, StringType
from .model import DtNode, DtValue

# Properties dt-schema allows on every node of a closed binding (its fixups add them): devicetree
# plumbing, not part of a binding's model.
GENERIC_PROPERTIES = frozenset(
    {"phandle", "linux,phandle", "status", "secure-status", "pinctrl-names"}
    | {f"bootph-{x}" for x in ("pre-sram", "verify", "pre-ram", "some-ram", "all")}
)
_GENERIC_PATTERN = re.compile(r"^pinctrl-[0-9]+$")


def is_generic(name: str) -> bool:
    return name in GENERIC_PROPERTIES or _GENERIC_PATTERN.match(name) is not None


def find_compatible(nodes: Iterable[DtNode], compatible: str) -> list[DtNode]:
    """The nodes whose ``compatible`` list names ``compatible`` (how dt-schema selects a binding)."""
    return [n for n in nodes if compatible in n.compatible]


def nodes_for_message(nodes: Iterable[DtNode], message: Message) -> list[DtNode]:
    """The nodes a devicetree message (binding) applies to, by its compatible strings."""
    wanted = set(message.devicetree.compatible) if message.devicetree else set()
    return [n for n in nodes if wanted & set(n.compatible)]


def by_phandle(nodes: Iterable[DtNode], phandle: int) -> DtNode | None:
    return next((n for n in nodes if n.phandle == phandle), None)


def monitored_batteries(nodes: Sequence[DtNode]) -> list[tuple[DtNode, DtNode]]:
    """(charger or fuel gauge, battery) for each ``monitored-battery = <&battery>`` that resolves."""
    out: list[tuple[DtNode, DtNode]] = []
    for node in nodes:
        value = node.properties.get("monitored-battery")
        cells = value.cells() if value is not None else None
        if cells and len(cells) == 1:
            target = by_phandle(nodes, cells[0])
            if target is not None:
                out.append((node, target))
    return out


def field_for(message: Message, name: str) -> Field | None:
    """The message field a property name selects: an exact name, else a matching pattern."""
    for f in message.fields:
        if f.pattern is None and f.name == name:
            return f
    for f in message.fields:
        if f.pattern is not None and re.search(f.pattern, name):
            return f
    return None


def node_to_model_dict(node: DtNode, message: Message) -> dict[str, Any]:
    """The node's properties as plain data keyed by property name.

    Generic devicetree properties (phandle, status, pinctrl-*) are left out. A property the
    binding does not define is kept (as its best-guess decoding) so ``from_dict`` reports it; a
    value whose bytes do not fit the field's type is passed as ``bytes`` so ``from_dict``
    rejects it with the property's name.
    """
    out: dict[str, Any] = {}
    for name, value in node.properties.items():
        if is_generic(name):
            continue
        f = field_for(message, name)
        out[name] = guess_value(value) if f is None else decode(value, f.type)
    return out


def guess_value(value: DtValue) -> Any:
    kind = value.guess()
    if kind == "flag":
        return True
    if kind == "strings":
        strings = value.strings() or []
        return strings[0] if len(strings) == 1 else strings
    if kind == "cells":
        return value.cells()
    return value.data


def decode(value: DtValue, ftype: object) -> Any:
    """The value as ``ftype`` wants it, or the raw bytes when it cannot be."""
    if isinstance(ftype, PrimitiveType):
        if ftype.kind is PrimitiveKind.BOOL:
            return True if value.is_flag else value.data
        ints = _ints(value, ftype)
        return ints[0] if ints is not None and len(ints) == 1 else (ints if ints is not None else value.data)
    if isinstance(ftype, StringType):
        strings = value.strings()
        if strings is None:
            return value.data
        return strings[0] if len(strings) == 1 else strings
    if isinstance(ftype, ArrayType):
        element = ftype.element
        if isinstance(element, StringType):
            return value.strings() if value.strings() is not None else value.data
        if isinstance(element, PrimitiveType):
            ints = _ints(value, element)
            return ints if ints is not None else value.data
        if isinstance(element, ArrayType) and isinstance(element.element, PrimitiveType):
            ints = _ints(value, element.element)
            if ints is None:
                return value.data
            stride = row_length(len(ints), ftype, element)
            return [ints[i : i + stride] for i in range(0, len(ints), stride)]
    return value.data


def _ints(value: DtValue, ptype: PrimitiveType) -> list[int] | None:
    if ptype.kind not in (PrimitiveKind.INT, PrimitiveKind.UINT) or ptype.bits not in (8, 16, 32, 64):
        return None
    if value.is_flag:
        return None
    return value.cells(ptype.bits, signed=ptype.kind is PrimitiveKind.INT)


def row_length(count: int, outer: ArrayType, inner: ArrayType) -> int:
    """How many values go in each matrix row, from the dimensions (dtschema's rule for blobs)."""
    if count == 0:
        return 1
    outer_lo, outer_hi = max(outer.min_length, 1), outer.capacity or count
    inner_lo, inner_hi = max(inner.min_length, 1), inner.capacity or count
    for rows in range(outer_lo, outer_hi + 1):
        if count % rows == 0 and inner_lo <= count // rows <= inner_hi:
            return count // rows
    if not inner.dynamic and inner.capacity:
        return inner.capacity
    if not outer.dynamic and outer.capacity:
        return max(count // outer.capacity, 1)
    return count

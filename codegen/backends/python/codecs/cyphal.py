"""Cyphal (UAVCAN v1) codec: ``encode`` / ``decode`` on every generated Cyphal class, bytes as pydsdl's
``serialize`` / ``deserialize`` give them.

Each class gets its layout as data (``CYPHAL_STRUCT``, a ``_cy.Struct`` of field specs) and the runtime
``_cyphal.py`` walks it: the wire rules live once there (see its docstring), so a difference from pydsdl is
one fix, not one per type. Also per class: ``EXTENT_BYTES``, ``SEALED`` and ``FIXED_PORT_ID``. A ``@union``
keeps one branch held as DroneCAN unions do (``union_field``, the ``_dc.Union`` rules of ``_dronecan.py``).
"""

from __future__ import annotations

from ....ir import ArrayType, CompositeType, Field, FieldType, Message, PrimitiveKind, PrimitiveType, Schema
from ....ir import SourceFormat as Fmt
from ..extensions import Contribution
from ..field_source import is_byte_array
from ..literals import py_literal
from ..module_context import ModuleContext
from ..runtime import copied
from ..views import ClassView
from .dronecan import union_members

_PRIMITIVE = {PrimitiveKind.UINT: "u", PrimitiveKind.INT: "i", PrimitiveKind.FLOAT: "f"}


def length_bits(capacity: int) -> int:
    """The width of a variable-length array's length prefix: the smallest of 8, 16, 32, 64 bits that holds
    the capacity (pydsdl's ``length_field_type``)."""
    return next(bits for bits in (8, 16, 32, 64) if capacity.bit_length() <= bits)


class _Specs:
    def __init__(self, ctx: ModuleContext) -> None:
        self.ctx = ctx

    def spec(self, t: FieldType, where: Field) -> str:
        """The runtime spec of a field type, as Python source."""
        if isinstance(t, PrimitiveType):
            if t.kind is PrimitiveKind.BOOL:
                return '("b",)'
            if t.kind is PrimitiveKind.VOID:
                return f'("v", {t.bits})'
            saturated = t.cast.value == "saturated"
            return f'("{_PRIMITIVE[t.kind]}", {t.bits}, {saturated})'
        if isinstance(t, ArrayType):
            assert t.capacity is not None, where  # DSDL arrays are always bounded
            prefix = length_bits(t.capacity) if t.dynamic else 0
            if is_byte_array(t):
                return f'("y", {t.capacity}, {prefix})'
            return f'("a", {self.spec(t.element, where)}, {t.capacity}, {prefix})'
        assert isinstance(t, CompositeType), t
        return f'("c", {self.ctx.factory(self.ctx.composite(t, where))})'


class _Codec:
    def contribute(self, msg: Message, ctx: ModuleContext, view: ClassView) -> Contribution:
        info = msg.cyphal
        if msg.format is not Fmt.CYPHAL or info is None:
            return Contribution()
        specs = _Specs(ctx)
        idents = iter(view.fields)
        entries = []
        for f in msg.fields:
            attr = "" if f.is_padding else next(idents).ident
            entries.append(f"({py_literal(attr)}, {specs.spec(f.type, f)})")
        fields = f"({', '.join(entries)},)" if entries else "()"
        layout = (
            f"_cy.Struct({py_literal(view.name)}, {fields}, sealed={info.sealed}, "
            f"extent_bytes={info.extent // 8}, union_tag_bits={info.union_tag_bits})"
        )
        lines = [
            "# how the fields lie on the wire (the runtime _cyphal.py walks it)",
            f"CYPHAL_STRUCT: _ClassVar[_cy.Struct] = {layout}",
            f"EXTENT_BYTES: _ClassVar[int] = {info.extent // 8}",
            f"SEALED: _ClassVar[bool] = {info.sealed}",
            f"FIXED_PORT_ID: _ClassVar[int | None] = {py_literal(info.fixed_port_id)}",
        ]
        imports = [f"from {ctx.root()} import _cyphal as _cy"]
        module_code: list[str] = []
        if info.union:
            # the branch rules are DroneCAN's (one held, the others None); only the spelling of the table differs
            union_members(msg, ctx, view, module_code, lines)
            imports.append(f"from {ctx.root()} import _dronecan as _dc")
        methods = [
            "def encode(self, *, with_delimiter_header: bool = False) -> bytes:",
            '    """The serialization (pydsdl\'s ``serialize``); the delimiter header only when asked (a delimited',
            '    type nested in another has one, a whole transfer has none)."""',
            "    return _cy.encode(self, self.CYPHAL_STRUCT, with_delimiter_header=with_delimiter_header)",
            "",
            "@classmethod",
            f"def decode(cls, data: bytes, /, *, with_delimiter_header: bool = False) -> {view.name}:",
            '    """An object read from its serialization (pydsdl\'s ``deserialize``): missing bits read as zero,',
            '    bytes beyond the last field are ignored; raises _cy.DecodeError on a bad length, tag or header."""',
            f"    obj: {view.name} = _cy.decode(",
            "        cls, data, cls.CYPHAL_STRUCT, with_delimiter_header=with_delimiter_header",
            "    )",
            "    return obj",
        ]
        body = "\n".join(lines) + "\n\n" + "\n".join(methods)
        class_body = "\n".join("    " + line if line else "" for line in body.split("\n"))
        return Contribution(class_body=class_body, module_code=tuple(module_code), imports=tuple(imports))

    def runtime_files(self, schema: Schema, header: str) -> dict[str, str]:
        cyphal = [m for m in schema.messages if m.format is Fmt.CYPHAL]
        if not cyphal:
            return {}
        if any(m.is_union for m in cyphal):
            return copied("_cyphal.py", "_dronecan.py")
        return copied("_cyphal.py")


EXTENSION = _Codec()

"""MAVLink 2 codec: payload encode/decode, frames and batch decoding for every MAVLink message.

Per message this emits one precompiled ``struct.Struct`` (the whole payload in wire order, as
``MavlinkInfo.wire_order`` says) and straight-line methods; frame handling, the checksum and the
id registry live in the runtime module ``_mavlink.py`` (copied from ``runtime/``), which imports the
registry of this package's messages from the generated ``_mavlink_registry.py``.
"""

from __future__ import annotations

from dataclasses import dataclass

from ....errors import BattgenError
from ....ir import ArrayType, Field, Message, PrimitiveKind, PrimitiveType, Schema, SourceFormat, StringType
from .. import naming
from ..extensions import Contribution
from ..literals import py_literal, text_literal
from ..module_context import ModuleContext
from ..runtime import copied
from ..views import ClassView, FieldView

RUNTIME = "_mavlink.py"
RUNTIME_FILES = (RUNTIME, "_mavlink_payload.py")  # copied from runtime/
REGISTRY = "_mavlink_registry.py"  # generated: the messages by id, imported by _mavlink.py
# names the codec adds to a class; a field with one of them would break it
_OWN_NAMES = frozenset(
    {"MSG_ID", "CRC_EXTRA", "MAVLINK_BASE_LENGTH", "MAVLINK_MAX_LENGTH", "encode_frame", "decode_frame", "decode_batch"}
)
_INT_FORMATS = {(PrimitiveKind.UINT, 8): "B", (PrimitiveKind.UINT, 16): "H", (PrimitiveKind.UINT, 32): "I",
                (PrimitiveKind.UINT, 64): "Q", (PrimitiveKind.INT, 8): "b", (PrimitiveKind.INT, 16): "h",
                (PrimitiveKind.INT, 32): "i", (PrimitiveKind.INT, 64): "q", (PrimitiveKind.FLOAT, 32): "f",
                (PrimitiveKind.FLOAT, 64): "d"}  # fmt: skip
_NUMPY = {"B": "u1", "b": "i1", "H": "<u2", "h": "<i2", "I": "<u4", "i": "<i4", "Q": "<u8", "q": "<i8", "f": "<f4",
          "d": "<f8"}  # fmt: skip


@dataclass(frozen=True)
class _Slot:
    """One field in wire order: its struct code, item count and how Python sees it."""

    ident: str
    source: str
    code: str  # struct code of one element ("s" for text, "B*" for a uint8 array held as bytes)
    count: int  # elements; 0 for a scalar
    fmt: str  # the field's piece of the struct format
    items: int  # values it takes in struct.pack / gives in unpack
    dtype: str  # numpy dtype of the column (without shape)

    @property
    def is_text(self) -> bool:
        return self.code == "s"

    @property
    def is_bytes(self) -> bool:
        return self.code == "B*"


def _slot(f: Field, view: FieldView, where: str) -> _Slot:
    t = f.type
    if isinstance(t, StringType) or (isinstance(t, PrimitiveType) and t.kind is PrimitiveKind.CHAR):
        size = t.capacity if isinstance(t, StringType) and t.capacity else 1
        return _Slot(view.ident, f.name, "s", size, f"{size}s", 1, f"S{size}")
    if isinstance(t, ArrayType) and isinstance(t.element, PrimitiveType) and t.capacity and not t.dynamic:
        code = _INT_FORMATS.get((t.element.kind, t.element.bits))
        if code is not None:
            if view.annotation == "bytes":
                return _Slot(view.ident, f.name, "B*", t.capacity, f"{t.capacity}s", 1, "u1")
            return _Slot(view.ident, f.name, code, t.capacity, f"{t.capacity}{code}", t.capacity, _NUMPY[code])
    if isinstance(t, PrimitiveType):
        code = _INT_FORMATS.get((t.kind, t.bits))
        if code is not None:
            return _Slot(view.ident, f.name, code, 0, code, 1, _NUMPY[code])
    raise BattgenError(f"{where}: field {f.name!r} has a type the MAVLink codec cannot send")


def _slots(msg: Message, view: ClassView) -> list[_Slot]:
    assert msg.mavlink is not None
    views = {fv.source_name: fv for fv in view.fields}
    where = str(msg.location)
    for fv in view.fields:
        if fv.ident in _OWN_NAMES:
            raise BattgenError(f"{where}: field {fv.source_name!r} clashes with the MAVLink codec's {fv.ident}")
    for name, _, _ in view.constants:
        if name in _OWN_NAMES:
            raise BattgenError(f"{where}: constant {name!r} clashes with the MAVLink codec's {name}")
    order = list(msg.mavlink.wire_order)
    if sorted(order) != sorted(views):
        raise BattgenError(f"{where}: MAVLink wire order {order} does not name the message's fields")
    return [_slot(msg.field(name), views[name], where) for name in order]


def _lines(*rows: str) -> str:
    return "\n".join(rows)


class _Writer:
    """Source of one message's struct, field table and methods."""

    def __init__(self, msg: Message, view: ClassView, ctx: ModuleContext) -> None:
        assert msg.mavlink is not None
        self.info = msg.mavlink
        self.cls = view.name
        self.msg_name = msg.name
        self.name = py_literal(msg.name)
        self.slots = _slots(msg, view)
        self.struct = ctx.constant(self.cls, "PAYLOAD")  # the whole payload, in wire order
        self.table = ctx.constant(self.cls, "FIELDS")
        self.dtype = ctx.constant(self.cls, "DTYPE")
        self.fmt = "<" + "".join(s.fmt for s in self.slots)
        self.positions: list[int] = []  # first struct item of each slot
        pos = 0
        for s in self.slots:
            self.positions.append(pos)
            pos += s.items
        self.n_items = pos

    def module_code(self) -> str:
        rows = [f"({py_literal(s.ident)}, {py_literal(s.source)}, {py_literal(s.code)}, {s.count})" for s in self.slots]
        table = ", ".join(rows) + ("," if len(rows) == 1 else "")
        dtype = ", ".join(
            f"({py_literal(s.source)}, {py_literal(s.dtype)}"
            + (f", ({s.count},))" if s.count and not s.is_text else ")")
            for s in self.slots
        )
        return _lines(
            "# the payload in wire order; (attribute, field, struct code, count) per field; numpy dtype",
            f"{self.struct} = _struct.Struct({text_literal(self.fmt)})",
            f"{self.table}: tuple[tuple[str, str, str, int], ...] = ({table})",
            f"{self.dtype}: list[tuple[_Any, ...]] = [{dtype}]",
        )

    def class_body(self) -> str:
        info = self.info
        return "\n".join(
            [
                f"    MSG_ID: _ClassVar[int] = {info.msg_id}",
                f"    CRC_EXTRA: _ClassVar[int] = {info.crc_extra}",
                f"    MAVLINK_BASE_LENGTH: _ClassVar[int] = {info.base_length}",
                f"    MAVLINK_MAX_LENGTH: _ClassVar[int] = {info.max_length}",
                "",
                self._encode(),
                "",
                self._decode(),
                "",
                self._frames(),
                "",
                self._batch(),
            ]
        )

    def _encode(self) -> str:
        args: list[str] = []
        pre: list[str] = []
        checks: list[str] = []
        for s in self.slots:
            attr = f"self.{s.ident}"
            if s.is_text:
                local = f"t_{s.ident}"
                pre.append(f'            {local} = {attr}.encode("utf-8", "surrogateescape")')
                args.append(local)
                checks.append(f"len({local}) > {s.count}")
            elif s.is_bytes:
                args.append(attr)
                checks.append(f"len({attr}) != {s.count}")
            elif s.count:
                args.append(f"*{attr}")
                checks.append(f"len({attr}) != {s.count}")
            else:
                args.append(attr)
        body = [
            "    def encode(self, *, truncate: bool = True) -> bytes:",
            f'        """The MAVLink 2 payload, {self.info.max_length} bytes in wire order; trailing zero bytes',
            "        are dropped (at least one byte is kept) unless ``truncate`` is False.",
            '        A value that does not fit its field raises EncodeError naming it."""',
            "        try:",
            *pre,
            f"            data = {self.struct}.pack({', '.join(args)})",
            "        except (_struct.error, TypeError, ValueError, AttributeError, OverflowError) as exc:",
            f"            raise _mav.explain({self.name}, self, {self.table}) from exc",
        ]
        if checks:
            body += [
                f"        if {' or '.join(checks)}:",
                f"            raise _mav.explain({self.name}, self, {self.table})",
            ]
        body += [
            "        if truncate:",
            '            return data.rstrip(b"\\x00") or b"\\x00"',
            "        return data",
        ]
        return _lines(*body)

    def _decode(self) -> str:
        size = self.info.max_length
        names = [f"v{i}" for i in range(self.n_items)]
        unpack = ", ".join(names) + ("," if len(names) == 1 else "")
        body = [
            "    @classmethod",
            f"    def decode(cls, data: _mav.BytesLike) -> {self.cls}:",
            f'        """A MAVLink 2 payload; a short one is zero-filled, one over {size} bytes is a DecodeError."""',
            f"        if len(data) != {size}:",
            f"            data = _mav.fill(data, {size}, {self.name})",
            f"        {unpack} = {self.struct}.unpack(data)",
            "        obj = object.__new__(cls)",
        ]
        for s, pos in zip(self.slots, self.positions, strict=True):
            if s.is_text:
                value = f"_mav.text({names[pos]})"
            elif s.count and not s.is_bytes:
                value = "[" + ", ".join(names[pos : pos + s.items]) + "]"
            else:
                value = names[pos]
            body.append(f"        obj.{s.ident} = {value}")
        body.append("        return obj")
        return _lines(*body)

    def _frames(self) -> str:
        info = self.info
        v1 = (
            f"            return _mav.frame_v1(self.encode(truncate=False)[:{info.base_length}], "
            f"{info.msg_id}, {py_literal(bytes((info.crc_extra,)))}, seq, sysid, compid, "
            "incompat_flags != 0 or compat_flags != 0 or signature is not None)"
        )
        if info.msg_id > 255:
            why = f"{self.msg_name}: message id {info.msg_id} does not fit a MAVLink 1 frame"
            v1 = f"            raise _mav.EncodeError({py_literal(why)})"
        return _lines(
            "    def encode_frame(",
            "        self,",
            "        *,",
            "        seq: int = 0,",
            "        sysid: int = 1,",
            "        compid: int = 1,",
            "        mavlink1: bool = False,",
            "        incompat_flags: int = 0,",
            "        compat_flags: int = 0,",
            "        signature: bytes | None = None,",
            "    ) -> bytes:",
            '        """A whole frame: MAVLink 2 (0xFD, truncated payload, CRC with CRC_EXTRA; a 13-byte',
            "        ``signature`` is appended and flagged, not computed) or, with ``mavlink1``, MAVLink 1",
            '        (0xFE, the base payload without extensions; message ids below 256 only)."""',
            "        if mavlink1:",
            v1,
            f"        return _mav.frame_v2(self.encode(), {info.msg_id}, {py_literal(bytes((info.crc_extra,)))}, seq, "
            "sysid, compid, incompat_flags, compat_flags, signature)",
            "",
            "    @classmethod",
            f"    def decode_frame(cls, data: _mav.BytesLike) -> {self.cls}:",
            '        """One whole MAVLink 1 or 2 frame of this message (CRC checked; a signature is skipped);',
            '        _mavlink.parse_frame gives the header fields."""',
            f"        payload = _mav.frame_payload(data, {info.msg_id}, {py_literal(bytes((info.crc_extra,)))}, "
            f"{info.max_length}, {self.name})",
            "        return cls.decode(payload)",
        )

    def _batch(self) -> str:
        size = self.info.max_length
        entries = []
        for s, pos in zip(self.slots, self.positions, strict=True):
            if s.is_text:
                value = f"[_mav.text(b) for b in c[{pos}]]"
            elif s.count and not s.is_bytes:
                value = f"list(zip(*c[{pos}:{pos + s.items}], strict=True))"
            else:
                value = f"c[{pos}]"
            entries.append(f"            {py_literal(s.source)}: {value},")
        return _lines(
            "    @classmethod",
            "    def decode_batch(cls, data: _mav.BytesLike, *, use_numpy: bool | None = None) -> dict[str, _Any]:",
            f'        """Records of {size} bytes (zero-filled payloads) -> columns keyed by field name: numpy',
            "        arrays (structured dtype) when numpy is installed and ``use_numpy`` is not False, else",
            '        tuples from struct.iter_unpack (arrays as a tuple per record, text as str)."""',
            f"        arrays = _mav.numpy_columns(data, {size}, {self.dtype}, use_numpy, {self.name})",
            "        if arrays is not None:",
            "            return arrays",
            f"        c = _mav.struct_columns(data, {self.struct}, {self.name})",
            "        return {",
            *entries,
            "        }",
        )


class _Codec:
    def contribute(self, msg: Message, ctx: ModuleContext, view: ClassView) -> Contribution:
        if msg.format is not SourceFormat.MAVLINK or msg.mavlink is None:
            return Contribution()
        writer = _Writer(msg, view, ctx)
        return Contribution(
            class_body=writer.class_body(),
            module_code=(writer.module_code(),),
            imports=(f"from {ctx.root()} import {RUNTIME[:-3]} as _mav",),
        )

    def runtime_files(self, schema: Schema, header: str) -> dict[str, str]:
        messages = [m for m in schema.messages if m.format is SourceFormat.MAVLINK and m.mavlink is not None]
        if not messages:
            return {}
        registry: dict[int, tuple[int, int, str, int, str]] = {}
        for m in messages:
            assert m.mavlink is not None
            # the first definition of an id wins (messages come sorted by qualified name)
            registry.setdefault(
                m.mavlink.msg_id,
                (m.mavlink.msg_id, m.mavlink.crc_extra, naming.class_name(m), m.mavlink.max_length, m.name),
            )
        entries = [registry[k] for k in sorted(registry)]
        return {**copied(*RUNTIME_FILES), REGISTRY: _registry_module(header, entries, naming.module_path(messages[0]))}


def _registry_module(header: str, entries: list[tuple[int, int, str, int, str]], module: str) -> str:
    """The per-package part of the MAVLink runtime: the message registry the copied ``_mavlink.py`` imports."""
    lines = [
        header,
        '"""The MAVLink messages of this package by id, for the runtime module ``_mavlink``."""',
        "",
        "# msgid -> (CRC_EXTRA, class name, MAVLINK_MAX_LENGTH, MAVLink name) of every generated message",
        "REGISTRY: dict[int, tuple[int, str, int, str]] = {",
        *(f"    {i}: ({crc}, {py_literal(name)}, {size}, {py_literal(mav)})," for i, crc, name, size, mav in entries),
        "}",
        f"MODULE = {py_literal(module)}  # the generated module holding the classes, relative to this package",
    ]
    return "\n".join(lines) + "\n"


EXTENSION = _Codec()

"""The uORB codec: PX4's C struct layout as ``encode``/``decode``, batch decoding into columns,
and the hooks the generated ULog runtime (``_ulog.py``) uses to write and read PX4 logs.

Per message the generated module gets precompiled ``struct.Struct`` objects: one with nested
messages inlined (decode: one ``unpack`` per record, then straight-line attribute stores) and one
with each nested message as a byte string (encode: nested messages encode themselves, so a bad
value names its full path). Split of responsibilities:

- here (toolchain): everything that depends on the IR -- formats, offsets, column names, code;
- ``_uorb.py`` (runtime): errors, C strings, the batch column decoder (``struct``, numpy optional);
- ``_ulog.py`` (runtime, with its parts ``_ulog_*.py``): the ULog file format, writer, reader and
  schema-vs-log comparison, driven by each class's ``ulog_format()``; standard library only, so a
  vendored package reads logs.
"""

from __future__ import annotations

from collections.abc import Callable

from ....errors import BattgenError
from ....ir import Message, Schema, SourceFormat
from .. import naming
from ..extensions import Contribution
from ..literals import py_literal, text_literal
from ..module_context import ClassRef, ModuleContext
from ..runtime import copied
from ..views import ClassView, class_view
from .uorb_layout import Part, column_format, columns, parts, snake, struct_format, trailing_padding
from .uorb_layout import compress as compress_codes

RUNTIME_FILES = ("_uorb.py", "_ulog.py", "_ulog_compare.py", "_ulog_format.py", "_ulog_parse.py", "_ulog_writer.py")
_ADDED = ("UORB_FORMAT", "UORB_SIZE", "UORB_SIZE_NO_PADDING", "UORB_TOPICS")
_METHODS = ("encode", "decode", "decode_batch", "ulog_format", "from_ulog")
_ERRORS = "(_struct.error, TypeError, OverflowError)"


class _Codec:
    def contribute(self, msg: Message, ctx: ModuleContext, view: ClassView) -> Contribution:
        if msg.format is not SourceFormat.UORB or msg.uorb is None:
            return Contribution()
        _check_names(msg, view)
        gen = _Generator(ctx, msg, view)
        return Contribution(
            class_body=gen.class_body(),
            module_code=tuple(gen.module_code),
            imports=("from " + ctx.root() + " import _uorb", "from " + ctx.root() + " import _ulog"),
        )

    def runtime_files(self, schema: Schema, header: str) -> dict[str, str]:
        if not any(m.format is SourceFormat.UORB for m in schema.messages):
            return {}
        return copied(*RUNTIME_FILES)


EXTENSION = _Codec()


def _check_names(msg: Message, view: ClassView) -> None:
    taken = {f.ident for f in view.fields} | {name for name, _, _ in view.constants}
    for name in (*_ADDED, *_METHODS):
        if name in taken:
            raise BattgenError(f"{msg.location}: {msg.qualified_name} defines {name!r}, a name the uORB codec needs")


class _Generator:
    """Source for one message; nested messages add helpers to ``module_code`` (deduplicated by text)."""

    def __init__(self, ctx: ModuleContext, msg: Message, view: ClassView) -> None:
        self.ctx = ctx
        self.schema = ctx.schema
        self.msg = msg
        self.view = view
        self.cls = view.name
        self.module_code: list[str] = []
        self.parts = parts(self.schema, msg)
        self.idents = {f.source_name: f.ident for f in view.fields}
        self.helpers: dict[str, None] = {}  # nested-message builders, in first-use order
        self.struct = ctx.constant(self.cls, "STRUCT")  # the C struct, nested messages inlined
        self.columns = ctx.constant(self.cls, "COLUMNS")
        self.packed_fields = ctx.constant(self.cls, "PACKED_FIELDS")

    # -- names -------------------------------------------------------------------------------

    def class_expr(self, nested: Message) -> tuple[str, str]:
        """(runtime expression, annotation) for a nested message's class."""
        ref: ClassRef = self.ctx.classes[nested.qualified_name]
        if ref.module == self.ctx.module:
            return ref.name, ref.name
        return self.ctx.factory(ref) + "()", self.ctx.annotation_name(ref)

    def nested_view(self, nested: Message) -> ClassView:
        return class_view(self.ctx, nested)

    # -- class body --------------------------------------------------------------------------

    def class_body(self) -> str:
        info = self.msg.uorb
        assert info is not None
        size = info.struct_size
        no_pad = size - trailing_padding(self.schema, self.msg)
        full_fmt = struct_format(self.schema, self.msg)
        attrs = [
            f"UORB_FORMAT: _ClassVar[str] = {text_literal(full_fmt)}",
            f"UORB_SIZE: _ClassVar[int] = {size}",
            f"UORB_SIZE_NO_PADDING: _ClassVar[int] = {no_pad}",
            f"UORB_TOPICS: _ClassVar[tuple[str, ...]] = {py_literal(tuple(info.topics))}",
        ]
        if not any(c.name == "MESSAGE_VERSION" for c in self.msg.constants):
            attrs.append(f"MESSAGE_VERSION: _ClassVar[int | None] = {py_literal(info.message_version)}")
        blocks = [
            "\n".join(attrs),
            self.encode_method(size),
            self.decode_method(size, no_pad),
            self.batch_method(size),
            self.ulog_methods(),
        ]
        self.module_code.append(self.structs(full_fmt, no_pad != size))
        self.module_code.extend(self.helpers)
        self.module_code.append(self.columns_constant(size))
        self.module_code.append(self.check_table())
        return _indent("\n\n".join(blocks), 4) + "\n"

    def structs(self, full_fmt: str, has_trailing: bool) -> str:
        enc = "<" + compress_codes([_encode_code(p) for p in self.parts])
        lines = [
            "# the C struct, nested messages inlined (decoding reads them in place)",
            f"{self.struct} = _struct.Struct({text_literal(full_fmt)})",
        ]
        if has_trailing:
            short = struct_format(self.schema, self.msg, trailing=False)
            lines += [
                "# without the trailing padding, which ULog records leave out",
                f"{self.ctx.constant(self.cls, 'UNPADDED')} = _struct.Struct({text_literal(short)})",
            ]
        if enc != full_fmt:
            lines += [
                "# nested messages as bytes: each encodes itself, so an error names its full path",
                f"{self.ctx.constant(self.cls, 'ENCODE_STRUCT')} = _struct.Struct({text_literal(enc)})",
            ]
        return "\n".join(lines)

    def encode_method(self, size: int) -> str:
        enc = "<" + compress_codes([_encode_code(p) for p in self.parts])
        struct_name = self.struct
        if enc != struct_format(self.schema, self.msg):
            struct_name = self.ctx.constant(self.cls, "ENCODE_STRUCT")
        args = [a for p in self.parts if (a := self.encode_arg(p))]
        return "\n".join(
            [
                "def encode(self) -> bytes:",
                f'    """PX4\'s C struct of this message: {size} bytes, little-endian, padding zeroed."""',
                "    try:",
                f"        return {struct_name}.pack({', '.join(args)})",
                f"    except {_ERRORS} as exc:",
                f"        raise _uorb.encode_error({py_literal(self.cls)}, self, {self.packed_fields}, exc) from None",
            ]
        )

    def encode_arg(self, p: Part) -> str:
        """The pack argument for one slot ('' for padding); helpers name the field in errors."""
        if p.kind == "pad":
            return ""
        attr = f"self.{self.idents[p.name]}"
        where = py_literal(f"{self.cls}.{p.name}")
        if p.kind == "scalar":
            return attr
        if p.kind == "array":
            return f"*{attr}"
        if p.kind == "char":
            return f"_uorb.char_encode({attr}, {where})"
        if p.kind == "string":
            return f"_uorb.cstr_encode({attr}, {p.count}, {where})"
        if p.kind == "bytes":
            return f"_uorb.fixed_bytes({attr}, {p.count}, {where})"
        assert p.nested is not None
        cls_expr, _ = self.class_expr(p.nested)
        if p.kind == "nested":
            return f"_uorb.nested({attr}, {cls_expr}, {where})"
        return f"_uorb.nested_array({attr}, {p.count}, {cls_expr}, {where})"

    def decode_method(self, size: int, no_pad: int) -> str:
        accepted = f"len(data) != {size}" + (f" and len(data) != {no_pad}" if no_pad != size else "")
        expected = f"{size} bytes" + (f" (or {no_pad} without the trailing padding)" if no_pad != size else "")
        struct_name = self.ctx.constant(self.cls, "UNPADDED") if no_pad != size else self.struct
        body = self.build_lines(self.msg, self.parts, "o", "cls", lambda i: str(i))
        return "\n".join(
            [
                "@classmethod",
                f"def decode(cls, data: bytes) -> {self.cls}:",
                f'    """From PX4\'s C struct: {expected}."""',
                f"    if {accepted}:",
                f"        raise _uorb.DecodeError({py_literal(f'{self.cls}: expected {expected}, got ')}"
                " + str(len(data)))",
                f"    v = {struct_name}.unpack_from(data)",
                *("    " + line for line in body),
                "    return o",
            ]
        )

    def build_lines(
        self, msg: Message, msg_parts: list[Part], obj: str, cls_expr: str, index: Callable[[int], str]
    ) -> list[str]:
        """Statements creating ``obj`` from the unpacked tuple ``v`` (index(i) spells position i)."""
        idents = self.idents if msg is self.msg else {f.source_name: f.ident for f in self.nested_view(msg).fields}
        lines = [f"{obj} = {cls_expr}.__new__({cls_expr})"]
        i = 0
        for p in msg_parts:
            if p.kind == "pad":
                continue
            attr = f"{obj}.{idents[p.name]}"
            if p.kind == "scalar":
                value = f"v[{index(i)}]"
            elif p.kind == "char":
                value = f"_uorb.char_decode(v[{index(i)}])"
            elif p.kind == "string":
                value = f"_uorb.cstr_decode(v[{index(i)}])"
            elif p.kind == "bytes":
                value = f"v[{index(i)}]"
            elif p.kind == "array":
                value = f"list(v[{index(i)}:{index(i + p.values)}])"
            else:
                assert p.nested is not None
                helper = self.nested_builder(p.nested)
                step = p.values // max(p.count, 1)
                if p.kind == "nested":
                    value = f"{helper}(v, {index(i)})"
                else:
                    value = "[" + ", ".join(f"{helper}(v, {index(i + k * step)})" for k in range(p.count)) + "]"
            lines.append(f"{attr} = {value}")
            i += p.values
        return lines

    def nested_builder(self, nested: Message) -> str:
        """Name of a module-level function building ``nested`` from the parent's unpacked tuple."""
        cls_expr, annotation = self.class_expr(nested)
        name = self.ctx.private_name(f"_{naming.lower_snake(naming.class_name(nested))}_from_values", nested)
        body = self.build_lines(nested, parts(self.schema, nested), "o", cls_expr, lambda i: f"i + {i}" if i else "i")
        code = "\n".join(
            [
                f"def {name}(v: tuple[_Any, ...], i: int) -> {annotation}:",
                *("    " + line for line in body),
                "    return o",
            ]
        )
        self.helpers[code] = None
        return name

    def columns_constant(self, size: int) -> str:
        cols = list(columns(self.schema, self.msg))
        end = max((c.offset + c.size for c in cols), default=0)
        names, fmt = py_literal(tuple(c.name for c in cols)), text_literal(column_format(cols, end))
        np_types, offsets = py_literal(tuple(c.np_type for c in cols)), py_literal(tuple(c.offset for c in cols))
        return f"{self.columns} = _uorb.Columns({names}, {fmt}, {size}, {np_types}, {offsets})"

    def check_table(self) -> str:
        """(attribute, field, struct code, count) of the plain fields, for naming a bad value."""
        rows = []
        for p in self.parts:
            if p.kind in ("scalar", "array"):
                code = p.code[-1]
                rows.append((self.idents[p.name], p.name, code, p.count))
        return "\n".join(
            [
                "# (attribute, field, struct code, count) of the plain fields, to name a value that does not fit",
                f"{self.packed_fields}: tuple[tuple[str, str, str, int], ...] = {py_literal(tuple(rows))}",
            ]
        )

    def batch_method(self, size: int) -> str:
        return "\n".join(
            [
                "@classmethod",
                "def decode_batch(",
                "    cls,",
                "    buffer: bytes,",
                "    *,",
                "    stride: int | None = None,",
                "    use_numpy: bool | None = None,",
                "    copy: bool = True,",
                ") -> dict[str, _Any]:",
                '    """Columns of back-to-back records without an object per record, named as PX4 log',
                "    tools flatten them (``voltage_cell_v[3]``, ``nested.field``; char arrays as bytes).",
                "",
                f"    ``stride``: bytes per record, default {size} (UORB_SIZE_NO_PADDING for ULog data).",
                "    numpy arrays when numpy is installed (``use_numpy`` None) or required (True; views",
                "    into ``buffer`` unless ``copy``), else lists from ``struct.iter_unpack``.",
                '    """',
                f"    return {self.columns}.decode(buffer, stride, use_numpy=use_numpy, copy=copy)",
            ]
        )

    def ulog_methods(self) -> str:
        info = self.msg.uorb
        assert info is not None
        members = [self.member(p) for p in self.parts]
        return "\n".join(
            [
                "@classmethod",
                "def ulog_format(cls) -> _ulog.Format:",
                '    """The ULog format PX4\'s logger writes for this struct (nested formats attached)."""',
                f"    return _ulog.Format({py_literal(snake(self.msg.name))}, {_tuple(members)}, cls, "
                f"{py_literal(tuple(info.topics))}, {py_literal(info.message_version)})",
                "",
                "@classmethod",
                "def from_ulog(",
                "    cls, source: _ulog.Source | _ulog.Log, *, topic: str | None = None, multi_id: int | None = None",
                f") -> list[_ulog.Record[{self.cls}]]:",
                '    """Every record of this message in a ULog file (path, bytes, binary file or a read Log),',
                "    in file order: each a _ulog.Record saying its instance (multi_id), topic and offset.",
                "",
                "    Every instance unless ``multi_id`` names one; every topic of UORB_TOPICS unless ``topic``",
                "    names one. When the log's own format differs (an older PX4), fields are matched by name",
                "    (through PX4's renames), compatible types converted with range checks, and the log's",
                "    values the instance cannot hold kept in the record's ``extras`` (see _ulog.Log.compare).",
                '    """',
                "    log = source if isinstance(source, _ulog.Log) else _ulog.read(source)",
                "    return list(log.iter_records(cls, topic=topic, multi_id=multi_id))",
            ]
        )

    def member(self, p: Part) -> str:
        args = [py_literal(p.ctype), str(p.count), py_literal(p.name)]
        if p.kind == "pad":
            return f"_ulog.Member({', '.join(args)})"
        args += [py_literal(self.idents[p.name]), py_literal(p.kind)]
        if p.nested is not None:
            cls_expr, _ = self.class_expr(p.nested)
            args.append(f"{cls_expr}.ulog_format()")
        return f"_ulog.Member({', '.join(args)})"


def _tuple(items: list[str]) -> str:
    return "(" + ", ".join(items) + ("," if len(items) == 1 else "") + ")"


def _encode_code(p: Part) -> str:
    return f"{p.size}s" if p.nested is not None else p.code


def _indent(text: str, width: int) -> str:
    pad = " " * width
    return "\n".join(pad + line if line else "" for line in text.split("\n"))

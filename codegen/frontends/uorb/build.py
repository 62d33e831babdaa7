"""uORB ``.msg`` files -> IR Messages: fields, constants, enums and the PX4 struct layout.

Files are read once each; a field whose type names another message loads that file first, since
its padded size shapes this message's layout (:mod:`.layout`). Nesting cycles are refused.

Errors are collected, not raised one at a time: every bad line and field of every file lands in
``Loader.errors`` (a file nesting a broken one is left out without a second report), and
``Loader.warnings`` holds what was accepted with a warning.
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

from ...errors import BattgenError, ErrorList, SchemaError
from ...ir import (
    ArrayType,
    CompositeType,
    Constant,
    Field,
    FieldType,
    Location,
    Message,
    PrimitiveKind,
    PrimitiveType,
    Schema,
    SchemaWarning,
    SourceFormat,
    StringType,
    UorbInfo,
    units,
)
from ...text.files import display_path, is_file
from ...text.limits import read_schema_text
from .annotations import parse_comment, sentinel, text_sentinel
from .enums import build_enums
from .layout import Member, px4_layout
from .syntax import BUILTINS, ConstantLine, FieldLine, MsgText, parse_text

PREFIX = "uorb."
_MESSAGE_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")


def snake_case(name: str) -> str:
    """PX4's default topic name for a message file: ``BatteryStatusV0`` -> ``battery_status_v0``."""
    spaced = re.sub(r"(.)([A-Z][a-z]+)", r"\1_\2", name)
    return re.sub(r"([a-z0-9])([A-Z])", r"\1_\2", spaced).lower()


class NestedFailure(BattgenError):
    """A file could not be laid out because a message it nests has errors (already reported)."""


class Loader:
    """Parses files once each, following nested types, and refuses nesting cycles."""

    def __init__(self, root: Path | None) -> None:
        self.root = root
        self.done: dict[Path, Message] = {}
        self.names: dict[str, str] = {}  # qualified name -> file it came from
        self.active: list[Path] = []
        self.failed: set[Path] = set()
        self.errors: list[BattgenError] = []  # every problem found, in the order found
        self.warnings: list[SchemaWarning] = []

    def schema(self) -> Schema:
        messages = sorted(self.done.values(), key=lambda m: m.qualified_name)
        return Schema(
            messages=tuple(messages),
            sources=tuple(sorted(m.location.file for m in messages)),
            warnings=tuple(self.warnings),
        )

    def raise_errors(self) -> None:
        ErrorList.raise_if_any(self.errors)

    def load(self, path: Path) -> Message:
        """The message of one file; on errors (recorded in ``errors``) raises NestedFailure."""
        key = path.resolve()
        if key in self.done:
            return self.done[key]
        if key in self.failed:
            raise NestedFailure(f"{path}: has errors")
        display = display_path(path, self.root)
        self.active.append(key)
        try:
            message = self._load(path, display)
        except NestedFailure:
            self.failed.add(key)
            raise
        except BattgenError as error:
            self.failed.add(key)
            self.errors.append(error)
            raise NestedFailure(f"{display}: has errors") from error
        finally:
            self.active.pop()
        self.done[key] = message
        self.names[message.qualified_name] = display
        return message

    def _load(self, path: Path, display: str) -> Message:
        if not _MESSAGE_NAME.match(path.stem):
            raise SchemaError(
                display, 1, f"expected a file named after its message (letters, digits, '_'), got '{path.name}'"
            )
        qualified = PREFIX + path.stem
        if qualified in self.names:
            raise SchemaError(
                display, 1, f"expected a unique message name: {qualified} is also defined in {self.names[qualified]}"
            )
        errors: list[SchemaError] = []
        text = parse_text(read_schema_text(path, display), display, errors)
        return self._build(path, display, text, list(errors))

    def _build(self, path: Path, display: str, text: MsgText, errors: list[BattgenError]) -> Message:
        qualified = PREFIX + path.stem
        constants = tuple(_constant(c, display) for c in text.items if isinstance(c, ConstantLine))
        values = {c.name: c.value for c in constants if not isinstance(c.value, str)}
        fields: list[Field] = []
        members: list[Member] = []
        nested_failed = False
        for item in text.items:
            if not isinstance(item, FieldLine):
                continue
            try:
                fields.append(self._field(item, qualified, values, constants, display))
                members.append(self._member(path, item, display))
            except NestedFailure:
                nested_failed = True
            except SchemaError as error:
                errors.append(error)
        if not errors and not nested_failed:
            try:
                _check_timestamp(fields, display)
                enums = build_enums(qualified, fields, constants, display)
                version = _message_version(text, display)
            except SchemaError as error:
                errors.append(error)
        if errors:
            raise ErrorList(errors) if len(errors) > 1 else errors[0]
        if nested_failed:
            raise NestedFailure(f"{display}: nests a message with errors")
        size, layout = px4_layout(members)
        return Message(
            name=path.stem,
            qualified_name=qualified,
            format=SourceFormat.UORB,
            location=Location(display, 1),
            doc=text.doc,
            fields=tuple(fields),
            constants=constants,
            enums=enums,
            uorb=UorbInfo(
                message_version=version,
                topics=text.topics or (snake_case(path.stem),),
                struct_size=size,
                layout=layout,
            ),
        )

    def _field(
        self,
        item: FieldLine,
        qualified: str,
        values: dict[str, int | float | bool],
        constants: tuple[Constant, ...],
        file: str,
    ) -> Field:
        """The field, with what it was accepted despite reported as warnings."""
        field, warned = _field(item, qualified, values, file)
        for prefix in [e.rsplit(".", 1)[-1] for e in field.enums]:
            if not any(c.name.startswith(prefix + "_") for c in constants):
                # PX4's doc linter warns about such constants ("Prefix not in @enum field metadata")
                # and its generator does not care: keep the field, without an enum of no entries
                others = sorted({c.name.split("_", 1)[0] for c in constants if c.name != "MESSAGE_VERSION"})
                hint = f" (this message's constants start with {', '.join(o + '_' for o in others)})" if others else ""
                warned.append(
                    (
                        "enum-prefix",
                        f"'[@enum {prefix}]' names no constant {prefix}_* in this message{hint}; "
                        "the field is read without that enum",
                    )
                )
                field = dataclasses.replace(
                    field,
                    enums=tuple(e for e in field.enums if not e.endswith("." + prefix)),
                    annotations=(*field.annotations, ("enum", prefix)),
                )
        self.warnings.extend(SchemaWarning(Location(file, item.line), kind, text) for kind, text in warned)
        return field

    def _member(self, path: Path, item: FieldLine, display: str) -> Member:
        count = item.array_len or 1
        if item.base in BUILTINS:
            return Member(item.name, BUILTINS[item.base].bits // 8, count)
        nested = path.parent / f"{item.base}.msg"
        if not is_file(nested):
            raise SchemaError(
                display, item.line, f"expected a builtin type or a message defined in {item.base}.msg next to this file"
            )
        if nested.resolve() in self.active:
            raise SchemaError(display, item.line, f"expected no nesting cycle: {item.base} contains this message")
        child = self.load(nested)
        assert child.uorb is not None  # every uORB message carries its layout
        return Member(item.name, 0, count, child.uorb.struct_size)


def _constant(item: ConstantLine, file: str) -> Constant:
    return Constant(item.name, item.type, item.value, item.comment, Location(file, item.line))


def _field(
    item: FieldLine, qualified: str, constants: dict[str, int | float | bool], file: str
) -> tuple[Field, list[tuple[str, str]]]:
    element = BUILTINS.get(item.base)
    float32 = element is not None and element.kind is PrimitiveKind.FLOAT and element.bits == 32
    notes = parse_comment(item.comment, file, item.line, float32=float32)
    warnings = list(notes.warnings)
    ftype = _field_type(item, element)
    invalid = None
    if notes.invalid is not None and isinstance(ftype, StringType):
        invalid, warned = text_sentinel(notes.invalid[0], file, item.line)
        warnings.extend([warned] if warned else [])
    elif notes.invalid is not None:
        numeric = element if element is not None and element.kind is not PrimitiveKind.CHAR else None
        invalid = sentinel(notes.invalid[0], numeric, item.array_len is not None, constants, file, item.line)
    if notes.enums and (element is None or element.kind not in (PrimitiveKind.INT, PrimitiveKind.UINT)):
        raise SchemaError(file, item.line, "expected '@enum' only on integer fields")
    unit = None
    if notes.unit_text is not None:
        unit = units.lookup(notes.unit_text) or units.opaque(notes.unit_text)
    field = Field(
        name=item.name,
        type=ftype,
        location=Location(file, item.line),
        doc=notes.doc,
        unit=unit,
        unit_text=notes.unit_text,
        range=notes.range,
        invalid=invalid,
        enums=tuple(f"{qualified}.{prefix}" for prefix in notes.enums),
        annotations=notes.annotations,
        frame=notes.frame,
    )
    return field, warnings


def _field_type(item: FieldLine, element: PrimitiveType | None) -> FieldType:
    scalar: PrimitiveType | CompositeType = element if element is not None else CompositeType(PREFIX + item.base)
    if item.array_len is None:
        return scalar
    if element is not None and element.kind is PrimitiveKind.CHAR:
        return StringType(capacity=item.array_len)  # char[N]: a NUL-padded string
    return ArrayType(element=scalar, capacity=item.array_len, dynamic=False)


def _check_timestamp(fields: list[Field], file: str) -> None:
    """PX4's generator refuses a message without a uint64 ``timestamp``."""
    for f in fields:
        if f.name == "timestamp":
            if f.type != BUILTINS["uint64"]:
                raise SchemaError(file, f.location.line, "expected 'timestamp' to be a uint64 (PX4 requires it)")
            return
    raise SchemaError(file, 1, "expected a 'uint64 timestamp' field (PX4 requires one in every message)")


def _message_version(text: MsgText, file: str) -> int | None:
    for item in text.items:
        if isinstance(item, ConstantLine) and item.name == "MESSAGE_VERSION":
            if item.type.kind not in (PrimitiveKind.INT, PrimitiveKind.UINT) or int(item.value) < 0:
                raise SchemaError(file, item.line, "expected MESSAGE_VERSION to be a non-negative integer constant")
            return int(item.value)
    return None

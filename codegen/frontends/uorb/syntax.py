"""Line syntax of a PX4 uORB .msg file: header doc, ``# TOPICS`` lines, fields and constants.

This layer only splits and checks lines; meaning (units, enums, layout) is added in :mod:`.build`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from ...errors import SchemaError
from ...ir import PrimitiveKind, PrimitiveType
from ...ir.fieldtypes import MAX_ARRAY_CAPACITY
from .values import describe_range, fits, parse_int, parse_number

BUILTINS: dict[str, PrimitiveType] = {
    "bool": PrimitiveType(PrimitiveKind.BOOL, 8),
    "char": PrimitiveType(PrimitiveKind.CHAR, 8),
    "byte": PrimitiveType(PrimitiveKind.UINT, 8),  # an octet, as in PX4's IDL mapping
    **{f"int{b}": PrimitiveType(PrimitiveKind.INT, b) for b in (8, 16, 32, 64)},
    **{f"uint{b}": PrimitiveType(PrimitiveKind.UINT, b) for b in (8, 16, 32, 64)},
    "float32": PrimitiveType(PrimitiveKind.FLOAT, 32),
    "float64": PrimitiveType(PrimitiveKind.FLOAT, 64),
}
# ROS types PX4's C structs cannot hold (no fixed size)
UNSUPPORTED = frozenset({"string", "wstring", "time", "duration"})

_TYPE = re.compile(r"(?:[A-Za-z][A-Za-z0-9_]*/)?([A-Za-z][A-Za-z0-9_]*)(?:\[([^\]]*)\])?\Z")
_FIELD_NAME = re.compile(r"[a-z][a-z0-9_]*\Z")
_CONST_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")
_TOPIC_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
_TOPICS_LINE = re.compile(r"# TOPICS(?:\s(.*))?\Z")


@dataclass(frozen=True)
class FieldLine:
    line: int
    base: str  # type name without array suffix or package prefix
    array_len: int | None
    name: str
    comment: str


@dataclass(frozen=True)
class ConstantLine:
    line: int
    type: PrimitiveType
    name: str
    value: int | float | bool
    comment: str


@dataclass(frozen=True)
class MsgText:
    doc: str
    topics: tuple[str, ...]  # empty when the file has no ``# TOPICS`` line
    items: tuple[FieldLine | ConstantLine, ...]


def parse_text(text: str, file: str, errors: list[SchemaError] | None = None) -> MsgText:
    """The lines of a file. With ``errors`` given, a bad line is appended there and skipped, so one
    run reports every bad line; without, the first one is raised."""
    doc_lines: list[str] = []
    topics: list[str] = []
    items: list[FieldLine | ConstantLine] = []
    seen: dict[str, int] = {}
    in_header = True  # the doc block: leading comment lines, up to the first other line
    for number, raw in enumerate(text.split("\n"), start=1):
        line = raw.rstrip("\r").rstrip()
        stripped = line.strip()
        try:
            topics_match = _TOPICS_LINE.match(line)
            if topics_match:
                topics.extend(_topics(topics_match.group(1) or "", topics, file, number))
                continue
            if stripped.startswith("#"):
                if in_header:
                    body = stripped[1:]
                    doc_lines.append(body[1:] if body.startswith(" ") else body)
                continue  # later comment lines are internal comments
            if not stripped:
                in_header = in_header and not doc_lines
                continue
            in_header = False
            item = _statement(line, file, number)
            if item.name in seen:
                raise SchemaError(
                    file, number, f"expected a unique name: '{item.name}' is already defined on line {seen[item.name]}"
                )
        except SchemaError as error:
            if errors is None:
                raise
            errors.append(error)
            continue
        seen[item.name] = number
        items.append(item)
    return MsgText(doc="\n".join(doc_lines).strip("\n"), topics=tuple(topics), items=tuple(items))


def _topics(text: str, known: list[str], file: str, line: int) -> list[str]:
    names = text.split()
    if not names:
        raise SchemaError(file, line, "expected topic names after '# TOPICS'")
    for i, name in enumerate(names):
        if not _TOPIC_NAME.match(name):
            raise SchemaError(file, line, f"expected a topic name (letters, digits, '_'), got '{name}'")
        if name in known or name in names[:i]:
            raise SchemaError(file, line, f"expected distinct topic names: '{name}' is listed twice")
    return names


def _statement(line: str, file: str, number: int) -> FieldLine | ConstantLine:
    code, _, comment = line.partition("#")
    if "=" in re.sub(r"\[[^\]]*\]", "[]", code):  # '=' inside brackets is a bounded array, not a constant
        return _constant(code, comment.strip(), file, number)
    tokens = code.split()
    if len(tokens) != 2:
        raise SchemaError(file, number, "expected '<type> <name>' or '<type> <NAME> = <value>'")
    base, array_len = _type(tokens[0], file, number)
    if not _FIELD_NAME.match(tokens[1]):
        raise SchemaError(file, number, f"expected a lower-case field name (a-z, 0-9, '_'), got '{tokens[1]}'")
    return FieldLine(number, base, array_len, tokens[1], comment.strip())


def _type(token: str, file: str, line: int) -> tuple[str, int | None]:
    match = _TYPE.match(token)
    if not match:
        raise SchemaError(file, line, f"expected a type such as 'float32' or 'float32[4]', got '{token}'")
    base, size = match.group(1), match.group(2)
    if base in UNSUPPORTED:
        raise SchemaError(file, line, f"expected a fixed-size type: PX4 messages cannot hold '{base}'")
    if size is None:
        return base, None
    count = parse_int(size.strip()) if size.strip().isdigit() else None
    if count is None:
        raise SchemaError(
            file, line, f"expected a fixed array size such as [4], got '[{size}]' (PX4 has no dynamic arrays)"
        )
    if count < 1:
        raise SchemaError(file, line, f"expected an array size of at least 1, got {count}")
    if count > MAX_ARRAY_CAPACITY:
        raise SchemaError(
            file, line, f"expected an array size of at most {MAX_ARRAY_CAPACITY} (docs/limits.md), got {count}"
        )
    return base, count


def _constant(code: str, comment: str, file: str, line: int) -> ConstantLine:
    left, _, value_text = code.partition("=")
    tokens, value_text = left.split(), value_text.strip()
    if len(tokens) != 2 or not value_text or len(value_text.split()) != 1:
        raise SchemaError(file, line, "expected a constant '<type> <NAME> = <value>'")
    type_name, name = tokens
    ptype = BUILTINS.get(type_name)
    if ptype is None:
        raise SchemaError(file, line, f"expected a builtin scalar type for constant '{name}', got '{type_name}'")
    if not _CONST_NAME.match(name):
        raise SchemaError(file, line, f"expected a constant name (letters, digits, '_'), got '{name}'")
    return ConstantLine(line, ptype, name, constant_value(ptype, value_text, file, line), comment)


def constant_value(ptype: PrimitiveType, text: str, file: str, line: int) -> int | float | bool:
    """The value of a constant of ``ptype`` written as ``text``."""
    if ptype.kind is PrimitiveKind.BOOL:
        spelled = text.lower()
        if spelled not in ("true", "false", "1", "0"):
            raise SchemaError(file, line, f"expected true, false, 1 or 0 for a bool constant, got '{text}'")
        return spelled in ("true", "1")
    if ptype.kind is PrimitiveKind.FLOAT:
        number = parse_number(text)
        if number is None or not fits(ptype, number):
            raise SchemaError(file, line, f"expected a {ptype.name} number, got '{text}'")
        return float(number)
    value = parse_int(text)
    if value is None:
        raise SchemaError(file, line, f"expected an integer for a {ptype.name} constant, got '{text}'")
    if not fits(ptype, value):
        raise SchemaError(file, line, f"expected a value in {describe_range(ptype)} for {ptype.name}, got {value}")
    return value

"""A safety pre-scan of MAVLink XML, run before pymavlink's parser sees a file.

pymavlink's mavparse eval()s enum entry values, reports few line numbers and may crash on
malformed attributes. This scan walks the same element paths with expat, rejects DTDs
(entity tricks) and every attribute form mavparse would choke on or eval unsafely, and keeps
what mavparse drops: line numbers, include lines, minValue/maxValue/default, <superseded>.
"""

from __future__ import annotations

import re
import xml.parsers.expat
from dataclasses import dataclass, field

from ...errors import SchemaError
from . import values as mavlink_values

IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
FIELD_TYPE = re.compile(r"(?P<base>float|double|char|u?int(?:8|16|32|64)_t)(?:\[(?P<len>[0-9]{1,3})\])?")
MAVLINK_VERSION_TYPE = "uint8_t_mavlink_version"
MAX_FIELDS = 64  # pymavlink's limit per message
MAX_MSG_ID = (1 << 24) - 1  # MAVLink 2 message ids are 24-bit
MAX_ARRAY = 255  # array lengths enter CRC_EXTRA as one byte

_FIELD_ATTRS = ("instance", "display", "print_format", "multiplier", "increment", "minValue", "maxValue", "default")


@dataclass
class ScannedField:
    name: str
    type_text: str
    line: int
    extension: bool
    attrs: dict[str, str]


@dataclass
class ScannedMessage:
    name: str
    msg_id: int
    line: int
    fields: list[ScannedField] = field(default_factory=list)
    has_extensions: bool = False
    superseded: tuple[str, str] | None = None


@dataclass
class ScannedEntry:
    name: str
    value: int
    line: int
    superseded: tuple[str, str] | None = None


@dataclass
class ScannedEnum:
    name: str
    line: int
    bitmask: bool
    entries: list[ScannedEntry] = field(default_factory=list)
    highest: int = 0  # pymavlink numbers an entry without value as highest so far + 1
    superseded: tuple[str, str] | None = None


@dataclass
class ScannedFile:
    includes: list[tuple[str, int]] = field(default_factory=list)
    messages: list[ScannedMessage] = field(default_factory=list)
    enums: list[ScannedEnum] = field(default_factory=list)


class _Scanner:
    def __init__(self, display: str) -> None:
        self.display = display
        self.out = ScannedFile()
        self.stack: list[str] = []
        self.text: list[str] = []
        self.parser = xml.parsers.expat.ParserCreate()
        p = self.parser
        p.SetParamEntityParsing(xml.parsers.expat.XML_PARAM_ENTITY_PARSING_NEVER)
        p.StartDoctypeDeclHandler = self._doctype
        p.EntityDeclHandler = self._entity
        p.StartElementHandler = self._start
        p.EndElementHandler = self._end
        p.CharacterDataHandler = self._chars

    def error(self, message: str) -> SchemaError:
        return SchemaError(self.display, self.parser.CurrentLineNumber, message)

    def _doctype(self, *_: object) -> None:
        raise self.error("expected no DOCTYPE (MAVLink XML needs no DTD; entity declarations are refused)")

    def _entity(self, *_: object) -> None:
        raise self.error("expected no ENTITY declarations")

    def _require(self, attrs: dict[str, str], names: tuple[str, ...], where: str) -> None:
        for name in names:
            if name not in attrs:
                raise self.error(f'expected a "{name}" attribute on <{where}>')

    def _name(self, attrs: dict[str, str], where: str) -> str:
        self._require(attrs, ("name",), where)
        name = attrs["name"]
        if not IDENTIFIER.fullmatch(name):
            raise self.error(f"expected an identifier as <{where}> name, got {name!r}")
        return name

    def _flag(self, attrs: dict[str, str], name: str, where: str) -> bool:
        value = attrs.get(name, "false")
        if value not in ("true", "false"):
            raise self.error(f'expected {name}="true" or "false" on <{where}>, got {value!r}')
        return value == "true"

    def _start(self, tag: str, attrs: dict[str, str]) -> None:
        self.stack.append(tag)
        self.text = []
        path = ".".join(self.stack)
        if len(self.stack) == 1 and tag != "mavlink":
            raise self.error(f"expected <mavlink> as the root element, got <{tag}>")
        handler = _HANDLERS.get(path)
        if handler is not None:
            handler(self, attrs)

    def _message(self, attrs: dict[str, str]) -> None:
        name = self._name(attrs, "message")
        self._require(attrs, ("id",), "message")
        text = attrs["id"]
        if not re.fullmatch(r"[0-9]{1,8}", text) or int(text) > MAX_MSG_ID:
            raise self.error(f"expected a decimal message id from 0 to {MAX_MSG_ID}, got {text!r}")
        self.out.messages.append(ScannedMessage(name, int(text), self.parser.CurrentLineNumber))

    def _extensions(self, attrs: dict[str, str]) -> None:
        message = self.out.messages[-1]
        if message.has_extensions:
            raise self.error("expected at most one <extensions/> marker per message")
        message.has_extensions = True

    def _field(self, attrs: dict[str, str]) -> None:
        message = self.out.messages[-1]
        name = self._name(attrs, "field")
        self._require(attrs, ("type",), "field")
        type_text = attrs["type"]
        m = FIELD_TYPE.fullmatch(type_text)
        if type_text != MAVLINK_VERSION_TYPE and (m is None or (m["len"] and not 1 <= int(m["len"]) <= MAX_ARRAY)):
            raise self.error(
                f"expected a field type int8_t..uint64_t, float, double or char, optionally as an array "
                f"T[N] with N from 1 to {MAX_ARRAY} (or uint8_t_mavlink_version), got {type_text!r}"
            )
        if len(message.fields) == MAX_FIELDS:
            raise self.error(f"expected at most {MAX_FIELDS} fields in message {message.name}")
        self._flag(attrs, "instance", "field")
        kept = {k: v for k, v in attrs.items() if k in _FIELD_ATTRS}
        line = self.parser.CurrentLineNumber
        message.fields.append(ScannedField(name, type_text, line, message.has_extensions, kept))

    def _deprecated(self, attrs: dict[str, str]) -> None:
        self._require(attrs, ("since", "replaced_by"), "deprecated")

    def _superseded(self, attrs: dict[str, str]) -> tuple[str, str]:
        self._require(attrs, ("since", "replaced_by"), "superseded")
        return attrs["since"], attrs["replaced_by"]

    def _message_superseded(self, attrs: dict[str, str]) -> None:
        self.out.messages[-1].superseded = self._superseded(attrs)

    def _enum_superseded(self, attrs: dict[str, str]) -> None:
        self.out.enums[-1].superseded = self._superseded(attrs)

    def _entry_superseded(self, attrs: dict[str, str]) -> None:
        self.out.enums[-1].entries[-1].superseded = self._superseded(attrs)

    def _enum(self, attrs: dict[str, str]) -> None:
        name = self._name(attrs, "enum")
        bitmask = self._flag(attrs, "bitmask", "enum")
        self.out.enums.append(ScannedEnum(name, self.parser.CurrentLineNumber, bitmask))

    def _entry(self, attrs: dict[str, str]) -> None:
        enum = self.out.enums[-1]
        name = self._name(attrs, "entry")
        if "value" in attrs:
            value = mavlink_values.entry_value(attrs["value"])
            if value is None:
                raise self.error(
                    f"expected {mavlink_values.ENTRY_VALUE_FORMS} as value of {name}, got {attrs['value']!r}"
                )
        else:
            value = enum.highest + 1
        enum.highest = max(enum.highest, value)
        self._flag(attrs, "hasLocation", "entry")
        enum.entries.append(ScannedEntry(name, value, self.parser.CurrentLineNumber))

    def _param(self, attrs: dict[str, str]) -> None:
        self._require(attrs, ("index",), "param")
        if not re.fullmatch(r"[1-9][0-9]{0,2}", attrs["index"]):
            raise self.error(f"expected a positive decimal param index, got {attrs['index']!r}")

    def _chars(self, data: str) -> None:
        self.text.append(data)

    def _end(self, tag: str) -> None:
        path = ".".join(self.stack)
        text = "".join(self.text).strip()
        line = self.parser.CurrentLineNumber
        if path == "mavlink.include":
            if not text:
                raise self.error("expected a file name inside <include>")
            self.out.includes.append((text, line))
        elif path == "mavlink.version" and not re.fullmatch(r"[0-9]{1,3}", text):
            raise self.error(f"expected a decimal number inside <version>, got {text!r}")
        self.stack.pop()
        self.text = []


_HANDLERS = {
    "mavlink.messages.message": _Scanner._message,
    "mavlink.messages.message.extensions": _Scanner._extensions,
    "mavlink.messages.message.field": _Scanner._field,
    "mavlink.messages.message.deprecated": _Scanner._deprecated,
    "mavlink.messages.message.superseded": _Scanner._message_superseded,
    "mavlink.enums.enum": _Scanner._enum,
    "mavlink.enums.enum.deprecated": _Scanner._deprecated,
    "mavlink.enums.enum.superseded": _Scanner._enum_superseded,
    "mavlink.enums.enum.entry": _Scanner._entry,
    "mavlink.enums.enum.entry.deprecated": _Scanner._deprecated,
    "mavlink.enums.enum.entry.superseded": _Scanner._entry_superseded,
    "mavlink.enums.enum.entry.param": _Scanner._param,
}


def scan(data: bytes, display: str) -> ScannedFile:
    """Check one MAVLink XML document; SchemaError (file, line, expected form) on anything unsafe."""
    scanner = _Scanner(display)
    try:
        scanner.parser.Parse(data, True)
    except xml.parsers.expat.ExpatError as exc:
        message = xml.parsers.expat.errors.messages.get(exc.code, str(exc))
        raise SchemaError(display, exc.lineno, f"expected well-formed XML ({message})") from None
    return scanner.out

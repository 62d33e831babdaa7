"""A safety pre-scan of MAVLink XML, run before pymavlink's parser sees a file.

pymavlink's mavparse eval()s enum entry values, reports few line numbers and may crash on
malformed attributes. This scan walks the same element paths with the shared hardened expat
set-up (codegen.text.xml: no DTDs, no entities), rejects every attribute form mavparse would
choke on or eval unsafely, and keeps what mavparse drops: line numbers, include lines,
minValue/maxValue/default, <superseded>.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from ...text.xml import XmlReader
from .values import ENTRY_VALUE_FORMS, entry_value

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


class _Scanner(XmlReader):
    """Walks the elements in document order, checking each one as it opens (and includes and
    versions as they close, when their text is known)."""

    def __init__(self, display: str) -> None:
        super().__init__(display, no_dtd_because="MAVLink XML needs no DTD; entity declarations are refused")
        self.out = ScannedFile()
        self.stack: list[str] = []
        self.chars: list[str] = []

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

    def start(self, tag: str, attrs: dict[str, str]) -> None:
        self.stack.append(tag)
        self.chars = []
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
        self.out.messages.append(ScannedMessage(name, int(text), self.line))

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
        line = self.line
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
        self.out.enums.append(ScannedEnum(name, self.line, bitmask))

    def _entry(self, attrs: dict[str, str]) -> None:
        enum = self.out.enums[-1]
        name = self._name(attrs, "entry")
        if "value" in attrs:
            value = entry_value(attrs["value"])
            if value is None:
                raise self.error(f"expected {ENTRY_VALUE_FORMS} as value of {name}, got {attrs['value']!r}")
        else:
            value = enum.highest + 1
        enum.highest = max(enum.highest, value)
        self._flag(attrs, "hasLocation", "entry")
        enum.entries.append(ScannedEntry(name, value, self.line))

    def _command_param(self, attrs: dict[str, str]) -> None:
        # a MAV_CMD entry's <param index="N">: the command's N-th argument
        self._require(attrs, ("index",), "param")
        if not re.fullmatch(r"[1-9][0-9]{0,2}", attrs["index"]):
            raise self.error(f"expected a positive decimal param index, got {attrs['index']!r}")

    def text(self, data: str) -> None:
        self.chars.append(data)

    def end(self, tag: str) -> None:
        path = ".".join(self.stack)
        text = "".join(self.chars).strip()
        line = self.line
        if path == "mavlink.include":
            if not text:
                raise self.error("expected a file name inside <include>")
            self.out.includes.append((text, line))
        elif path == "mavlink.version" and not re.fullmatch(r"[0-9]{1,3}", text):
            raise self.error(f"expected a decimal number inside <version>, got {text!r}")
        self.stack.pop()
        self.chars = []


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
    "mavlink.enums.enum.entry.param": _Scanner._command_param,
}


def scan(data: bytes, display: str) -> ScannedFile:
    """Check one MAVLink XML document; SchemaError (file, line, expected form) on anything unsafe."""
    scanner = _Scanner(display)
    scanner.read(data)
    return scanner.out

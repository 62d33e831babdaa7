"""Python names for IR objects: modules, classes, attributes. Pure functions of the IR."""

from __future__ import annotations

import builtins
import enum
import keyword
import re

from ...ir import DronecanKind, Message, Schema, SourceFormat

_NON_IDENT = re.compile(r"[^0-9A-Za-z_]+")
_WORD_BOUNDARY = re.compile(r"(?<=[a-z0-9])(?=[A-Z])|(?<=[A-Z])(?=[A-Z][a-z])")
_REGEX_TOKENS = re.compile(r"\[[^\]]*\][+*?]?|\\d[+*?]?|[+*?]")
# The one clash rule (README "Names", under "Generated package"): a schema name that would clash with a
# name the generated code needs gets a trailing "_" (repeated while it still clashes). The generated
# modules import what they use under private aliases (``_struct``, ``_ClassVar``), which no schema
# name can spell (identifier() strips leading underscores), so what is left to avoid is below.
#
# Every member a generated class gets from the backend and its extensions (codecs, validators):
RESERVED_MEMBERS = frozenset(
    {
        # models
        "QUALIFIED_NAME", "to_dict", "from_dict",
        # validators
        "validate", "check", "is_known",
        # codecs, all formats
        "encode", "decode", "decode_batch",
        # DroneCAN
        "DATA_TYPE_ID", "DATA_TYPE_SIGNATURE", "union_field",
        # uORB / ULog
        "UORB_FORMAT", "UORB_SIZE", "UORB_SIZE_NO_PADDING", "UORB_TOPICS", "ulog_format", "from_ulog",
        # MAVLink
        "MSG_ID", "CRC_EXTRA", "MAVLINK_BASE_LENGTH", "MAVLINK_MAX_LENGTH", "encode_frame", "decode_frame",
    }
)  # fmt: skip
# Builtins a generated class body names unqualified (annotations, decorators): a member of that
# name would be what the rest of the class body sees (tests/backends/test_clashing_names.py keeps
# this list in step with the templates).
CLASS_SCOPE_NAMES = frozenset(
    {"bool", "bytearray", "bytes", "classmethod", "dict", "float", "int", "list", "object", "staticmethod", "str"}
    | {"range", "tuple"}  # range: the default of a fixed array of structures (Cyphal)
)
# What an enum member may not be called: the attributes IntEnum and IntFlag have (``mro`` is refused
# by enum itself; ``real`` or ``to_bytes`` would hide int's).
ENUM_MEMBERS = frozenset(
    {"mro", "name", "value"} | {n for base in (enum.IntEnum, enum.IntFlag) for n in dir(base) if not n.startswith("_")}
)
# A class is a module-level name: one spelled like a builtin (``ValueError``) would hide it from the
# generated methods that raise or call it.
_BUILTINS = frozenset(dir(builtins))


def _unclash(name: str, taken: frozenset[str] | set[str]) -> str:
    while name in taken:
        name += "_"
    return name


def identifier(text: str) -> str:
    """A valid, non-keyword Python identifier for a schema name (``voltage-min-design-microvolt``)."""
    name = _NON_IDENT.sub("_", text).strip("_") or "field"
    if name[0].isdigit():
        name = "_" + name
    if keyword.iskeyword(name) or keyword.issoftkeyword(name):
        name += "_"
    return _unclash(name, RESERVED_MEMBERS | CLASS_SCOPE_NAMES)


def class_identifier(name: str) -> str:
    """A generated class's name, clear of the builtins its module's code uses."""
    return _unclash(name, _BUILTINS)


def field_identifier(name: str, pattern: str | None = None) -> str:
    """Attribute name of a field; a devicetree pattern property ``^ocv-capacity-table-[0-9]+$``
    becomes ``ocv_capacity_table_n`` (its values keyed by full property name)."""
    if pattern is not None:
        stem = _REGEX_TOKENS.sub("N", pattern.strip("^$"))
        return identifier(stem.lower())
    return identifier(name)


def camel(text: str) -> str:
    """``BATTERY_STATUS`` / ``simple-battery`` / ``battery`` -> ``BatteryStatus`` / ``SimpleBattery``."""
    parts = [p for p in _NON_IDENT.split(text.replace("_", " ").replace("-", " ")) if p]
    words = [w for part in parts for w in part.split(" ") if w]
    if not words:
        return "Unnamed"
    if len(words) == 1 and any(c.islower() for c in words[0]) and words[0][0].isupper():
        result = words[0]  # already CamelCase (BatteryInfo)
    else:
        result = "".join(w[:1].upper() + w[1:].lower() for w in words)
    return identifier(result)


def upper_snake(name: str) -> str:
    """``BatteryStatusV0`` / ``voltage_cell_v`` -> ``BATTERY_STATUS_V0`` / ``VOLTAGE_CELL_V``."""
    spaced = _WORD_BOUNDARY.sub("_", name)
    return re.sub(r"_+", "_", spaced).strip("_").upper() or "UNNAMED"


def lower_snake(name: str) -> str:
    """``BatteryStatusV0`` -> ``battery_status_v0``."""
    return upper_snake(name).lower()


def module_path(msg: Message) -> str:
    """Dotted module (relative to the generated package) holding the message's class."""
    if msg.format is SourceFormat.MAVLINK:
        return "mavlink"
    if msg.format is SourceFormat.UORB:
        return "uorb"
    if msg.format is SourceFormat.PDEF:
        return "params"
    if msg.format is SourceFormat.DRONECAN and msg.dronecan is not None:
        namespace = msg.dronecan.full_name.rsplit(".", 1)[0]
        return "dronecan." + ".".join(identifier(p) for p in namespace.split("."))
    if msg.format is SourceFormat.CYPHAL and msg.cyphal is not None:
        namespace = (msg.cyphal.alias_of or msg.cyphal.full_name).rsplit(".", 1)[0]
        return "cyphal." + ".".join(identifier(p) for p in namespace.split("."))
    parts = msg.qualified_name.split(".")[:-1]
    return ".".join(identifier(p) for p in parts)


def class_name(msg: Message) -> str:
    if msg.format is SourceFormat.DRONECAN and msg.dronecan is not None:
        base = identifier(msg.dronecan.full_name.rsplit(".", 1)[-1])  # the DSDL name exactly: CBAT stays CBAT
        if msg.dronecan.kind is DronecanKind.REQUEST:
            return base + "Request"
        if msg.dronecan.kind is DronecanKind.RESPONSE:
            return base + "Response"
        return class_identifier(base)
    if msg.format is SourceFormat.CYPHAL:
        return class_identifier(msg.name)  # nunavut's spelling: Status_0_2, ExecuteCommand_1_3_Request
    if msg.format is SourceFormat.DEVICETREE and msg.devicetree is not None and len(msg.devicetree.compatible) == 1:
        return class_identifier(camel(msg.devicetree.compatible[0]))
    if msg.format is SourceFormat.PDEF:
        return class_identifier(camel(msg.name) + "Params")  # params.BATT -> BattParams
    return class_identifier(camel(msg.name))


def enum_member(entry_name: str, group: str) -> str:
    """Enum member name with the group prefix dropped (``WARNING_LOW`` in WARNING -> ``LOW``)."""
    prefix = group + "_"
    short = entry_name[len(prefix) :] if entry_name.startswith(prefix) and len(entry_name) > len(prefix) else entry_name
    name = identifier(short)
    if name.startswith("_"):  # a digit first (``CELLS_2S`` in CELLS): the whole name reads better than ``_2S``
        name = identifier(entry_name)
    return _unclash(name, ENUM_MEMBERS)


def module_classes(schema: Schema, module: str) -> frozenset[str]:
    """The names of the message classes of one generated module."""
    return frozenset(class_name(m) for m in schema.messages if module_path(m) == module)


def member_names(msg: Message, classes: frozenset[str]) -> dict[tuple[str, str], str]:
    """The attribute of each field and constant of ``msg``, keyed ``("field" | "constant", schema name)``.

    The one clash rule: a name that is taken (a reserved member, a builtin of the class body, a class
    of the same module that the class body may name, or an earlier member) gets a trailing ``_``
    until it is free. Every part of the backend names members through this function.
    """
    taken: set[str] = set(classes)
    out: dict[tuple[str, str], str] = {}
    for f in msg.fields:
        if f.is_padding:
            continue
        name = _unclash(field_identifier(f.name, f.pattern), taken)
        taken.add(name)
        out[("field", f.name)] = name
    for c in msg.constants:
        name = _unclash(identifier(c.name), taken)
        taken.add(name)
        out[("constant", c.name)] = name
    return out

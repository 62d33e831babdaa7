"""Python names for IR objects: modules, classes, attributes. Pure functions of the IR."""

from __future__ import annotations

import keyword
import re

from ...ir import DronecanKind, Message, SourceFormat

_NON_IDENT = re.compile(r"[^0-9A-Za-z_]+")
_WORD_BOUNDARY = re.compile(r"(?<=[a-z0-9])(?=[A-Z])|(?<=[A-Z])(?=[A-Z][a-z])")
_REGEX_TOKENS = re.compile(r"\[[^\]]*\][+*?]?|\\d[+*?]?|[+*?]")
# Every member a generated class gets from the backend and its extensions (codecs, validators):
# a schema field or constant with one of these names is renamed (a trailing "_"), never shadowing it.
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


def identifier(text: str) -> str:
    """A valid, non-keyword Python identifier for a schema name (``voltage-min-design-microvolt``)."""
    name = _NON_IDENT.sub("_", text).strip("_") or "field"
    if name[0].isdigit():
        name = "_" + name
    if keyword.iskeyword(name) or keyword.issoftkeyword(name) or name in RESERVED_MEMBERS:
        name += "_"
    return name


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
    parts = msg.qualified_name.split(".")[:-1]
    return ".".join(identifier(p) for p in parts)


def class_name(msg: Message) -> str:
    if msg.format is SourceFormat.DRONECAN and msg.dronecan is not None:
        base = identifier(msg.dronecan.full_name.rsplit(".", 1)[-1])  # the DSDL name exactly: CBAT stays CBAT
        if msg.dronecan.kind is DronecanKind.REQUEST:
            return base + "Request"
        if msg.dronecan.kind is DronecanKind.RESPONSE:
            return base + "Response"
        return base
    if msg.format is SourceFormat.DEVICETREE and msg.devicetree is not None and len(msg.devicetree.compatible) == 1:
        return camel(msg.devicetree.compatible[0])
    if msg.format is SourceFormat.PDEF:
        return camel(msg.name) + "Params"  # params.BATT -> BattParams
    return camel(msg.name)


def enum_member(entry_name: str, group: str) -> str:
    """Enum member name with the group prefix dropped (``WARNING_LOW`` in WARNING -> ``LOW``)."""
    prefix = group + "_"
    short = entry_name[len(prefix) :] if entry_name.startswith(prefix) and len(entry_name) > len(prefix) else entry_name
    name = identifier(short)
    if name.startswith("_") or name in ("name", "value"):
        name = identifier(entry_name)
    return name

"""Finding a message of a schema by the names a user gives it."""

from __future__ import annotations

from ...backends.python import naming
from ...errors import BattgenError, did_you_mean
from ...ir import Message, Schema

# The battery message each log or capture kind carries, where the user names none: what a ULog's battery_status
# topic holds, the battery message every MAVLink autopilot sends, the one every DroneCAN battery node sends. One
# table for validate, convert and report (a DataFlash log's BAT records have no message schema).
BATTERY_MESSAGES = {
    "ulog": "uorb.BatteryStatus",
    "tlog": "mavlink.BATTERY_STATUS",
    "mavlink": "mavlink.BATTERY_STATUS",
    "can": "dronecan.uavcan.equipment.power.BatteryInfo",
}
DATAFLASH_NOTE = (
    "a DataFlash log's battery records (BAT, CURR) have no message schema: 'battgen report', 'export' and 'failsafe' "
    "read them, and --message dronecan.<type> reads the DroneCAN messages of its CAN frames"
)


def message_aliases(msg: Message) -> set[str]:
    """The names a user may give for ``msg``: its qualified name, every dotted suffix of it, the
    source name, the generated class name, and for devicetree bindings the compatible strings."""
    parts = msg.qualified_name.split(".")
    names = {".".join(parts[i:]) for i in range(len(parts))}
    names.update((msg.name, naming.class_name(msg)))
    if msg.devicetree is not None:
        names.update(msg.devicetree.compatible)
    return names


def resolve_message(schema: Schema, name: str) -> Message:
    """The message called ``name``: exact qualified name first, else an unambiguous short form."""
    for msg in schema.messages:
        if msg.qualified_name == name:
            return msg
    matches = [m for m in schema.messages if name in message_aliases(m)]
    if not matches:
        folded = name.casefold()
        matches = [m for m in schema.messages if folded in {a.casefold() for a in message_aliases(m)}]
    if len(matches) == 1:
        return matches[0]
    if matches:
        candidates = ", ".join(m.qualified_name for m in matches)
        raise BattgenError(f"message name {name!r} is ambiguous: it could be {candidates}")
    hint = did_you_mean(name, (a for m in schema.messages for a in message_aliases(m)), what="message names")
    raise BattgenError(f"no message called {name!r} in the schemas; {hint}")

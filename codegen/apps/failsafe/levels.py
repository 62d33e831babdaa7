"""The failsafe's levels, and how a level shows in the battery messages.

uORB ``battery_status.warning`` and MAVLink ``BATTERY_STATUS.charge_state`` carry the level; their
values are the generated enums' of the bundled schemas, written out (a test holds them equal, so they follow the
message definitions).
"""

from __future__ import annotations

import enum
from collections.abc import Mapping
from typing import Any


class Level(enum.IntEnum):
    NONE = 0
    LOW = 1
    CRITICAL = 2


# The levels as the generated enums of the bundled schemas give them (uorb.BatteryStatusWarning,
# mavlink.MavBatteryChargeState), written out: importing the generated messages for two numbers cost a JSON Lines
# replay a fifth of its time. tests/apps/test_failsafe.py holds them equal to the generated enums, so a change of the
# message definitions fails there (as the Rust support's copy, codegen/backends/rust/support/failsafe.rs, would).
UORB_WARNING = {Level.NONE: 0, Level.LOW: 1, Level.CRITICAL: 2}  # BatteryStatusWarning NONE, LOW, CRITICAL
MAVLINK_CHARGE_STATE = {Level.NONE: 1, Level.LOW: 2, Level.CRITICAL: 3}  # MavBatteryChargeState OK, LOW, CRITICAL


def uorb_warning(level: Level) -> int:
    """The level as uORB battery_status.warning (generated enum BatteryStatusWarning)."""
    return UORB_WARNING[level]


def mavlink_charge_state(level: Level) -> int:
    """The level as MAVLink BATTERY_STATUS.charge_state (generated enum MavBatteryChargeState)."""
    return MAVLINK_CHARGE_STATE[level]


def apply_level(qualified_name: str, data: Mapping[str, Any], level: Level) -> dict[str, Any]:
    """A copy of converted message data with the failsafe level written in (uORB ``warning``,
    MAVLink ``charge_state``); other messages come back unchanged."""
    out = dict(data)
    if qualified_name.startswith("uorb.BatteryStatus"):
        out["warning"] = uorb_warning(level)
    elif qualified_name == "mavlink.BATTERY_STATUS":
        out["charge_state"] = mavlink_charge_state(level)
    return out

"""The failsafe's levels, and how a level shows in the battery messages.

uORB ``battery_status.warning`` and MAVLink ``BATTERY_STATUS.charge_state`` carry the level; their
values come from the generated enums of the bundled schemas (so they follow the message
definitions), found through :mod:`codegen.apps.schemas.package`.
"""

from __future__ import annotations

import enum
from collections.abc import Mapping
from typing import Any

from ..schemas.package import bundled_package, package_module


class Level(enum.IntEnum):
    NONE = 0
    LOW = 1
    CRITICAL = 2


def _enum(module: str, name: str) -> Any:
    """A generated enum of the bundled package (``uorb.BatteryStatusWarning``)."""
    return getattr(package_module(bundled_package(), module), name)


def uorb_warning(level: Level) -> int:
    """The level as uORB battery_status.warning (generated enum BatteryStatusWarning)."""
    W = _enum("uorb", "BatteryStatusWarning")
    return int({Level.NONE: W.NONE, Level.LOW: W.LOW, Level.CRITICAL: W.CRITICAL}[level])


def mavlink_charge_state(level: Level) -> int:
    """The level as MAVLink BATTERY_STATUS.charge_state (generated enum MavBatteryChargeState)."""
    C = _enum("mavlink", "MavBatteryChargeState")
    return int({Level.NONE: C.OK, Level.LOW: C.LOW, Level.CRITICAL: C.CRITICAL}[level])


def apply_level(qualified_name: str, data: Mapping[str, Any], level: Level) -> dict[str, Any]:
    """A copy of converted message data with the failsafe level written in (uORB ``warning``,
    MAVLink ``charge_state``); other messages come back unchanged."""
    out = dict(data)
    if qualified_name.startswith("uorb.BatteryStatus"):
        out["warning"] = uorb_warning(level)
    elif qualified_name == "mavlink.BATTERY_STATUS":
        out["charge_state"] = mavlink_charge_state(level)
    return out

"""Older ArduPilot battery parameter names and the names they carry today, so a log from older
firmware (ArduCopter 3.x logs ``FS_BATT_VOLTAGE``, ``FS_BATT_MAH``, ``FS_BATT_ENABLE``) replays with
the settings it flew with.

Facts from ArduPilot's parameter conversions: Copter 3.6 moved the vehicle's battery failsafe into
AP_BattMonitor (``FS_BATT_VOLTAGE`` -> ``BATT_LOW_VOLT``, ``FS_BATT_MAH`` -> ``BATT_LOW_MAH``,
``FS_BATT_ENABLE`` -> ``BATT_FS_LOW_ACT`` with the same values: 0 none, 1 land, 2 RTL), and the
multi-monitor rework renamed ``BATT_AMP_PERVOLT`` (``BATT2_AMP_PERVOL``, cut at 16 characters) to
``BATT_AMP_PERVLT``. A value the log also holds under today's name wins.
"""

from __future__ import annotations

from collections.abc import Mapping

RENAMES: dict[str, str] = {
    "FS_BATT_VOLTAGE": "BATT_LOW_VOLT",
    "FS_BATT_MAH": "BATT_LOW_MAH",
    "FS_BATT_ENABLE": "BATT_FS_LOW_ACT",
    "BATT_AMP_PERVOLT": "BATT_AMP_PERVLT",
    **{f"BATT{n}_AMP_PERVOL": f"BATT{n}_AMP_PERVLT" for n in range(2, 10)},
}


def with_current_names(parameters: Mapping[str, float]) -> dict[str, float]:
    """``parameters`` with each older name's value also under today's name (where that is absent)."""
    out = dict(parameters)
    for old, new in RENAMES.items():
        if old in parameters and new not in parameters:
            out[new] = parameters[old]
    return out

"""Older ArduPilot battery parameter names and the names they carry today, so a log or parameter file from older
firmware (ArduCopter before 3.6 names its battery failsafe ``FS_BATT_VOLTAGE``, ``FS_BATT_MAH``, ``FS_BATT_ENABLE``)
replays with the settings it flew with, and says so.

Facts from ArduPilot's parameter conversions, as QGroundControl's APMFirmwarePlugin remaps them for ArduCopter 3.6:
the vehicle's battery failsafe moved into AP_BattMonitor (``FS_BATT_VOLTAGE`` -> ``BATT_LOW_VOLT``, ``FS_BATT_MAH`` ->
``BATT_LOW_MAH``, ``FS_BATT_ENABLE`` -> ``BATT_FS_LOW_ACT`` with the same values: 0 none, 1 land, 2 RTL), the arming
voltages into it (``ARMING_MIN_VOLT`` -> ``BATT_ARM_VOLT``, ``ARMING_MIN_VOLT2`` -> ``BATT2_ARM_VOLT``), and the
multi-monitor rework renamed ``BATT_AMP_PERVOLT`` (``BATT2_AMP_PERVOL``, cut at 16 characters) to
``BATT_AMP_PERVLT``. A value the log also holds under today's name wins.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

RENAMES: dict[str, str] = {
    "FS_BATT_VOLTAGE": "BATT_LOW_VOLT",
    "FS_BATT_MAH": "BATT_LOW_MAH",
    "FS_BATT_ENABLE": "BATT_FS_LOW_ACT",
    "ARMING_MIN_VOLT": "BATT_ARM_VOLT",
    "ARMING_MIN_VOLT2": "BATT2_ARM_VOLT",
    "BATT_AMP_PERVOLT": "BATT_AMP_PERVLT",
    **{f"BATT{n}_AMP_PERVOL": f"BATT{n}_AMP_PERVLT" for n in range(2, 10)},
}


@dataclass(frozen=True)
class Renamed:
    """An older name found in a parameter set: its value is taken under today's name, unless that is set too."""

    old: str
    new: str
    value: float
    current: float | None  # today's name's own value, which wins

    def message(self) -> str:
        if self.current is None:
            return (
                f"{self.old} = {self.value:g} is the older name of {self.new}: replayed as {self.new} = {self.value:g}"
            )
        return f"{self.old} = {self.value:g} ignored: today's {self.new} = {self.current:g} is set too and wins"


def renamed(parameters: Mapping[str, float]) -> list[Renamed]:
    """Every older name of ``parameters``, in :data:`RENAMES` order."""
    return [
        Renamed(old, new, parameters[old], parameters.get(new)) for old, new in RENAMES.items() if old in parameters
    ]


def with_current_names(parameters: Mapping[str, float]) -> dict[str, float]:
    """``parameters`` with each older name's value also under today's name (where that is absent)."""
    out = dict(parameters)
    for r in renamed(parameters):
        if r.current is None:
            out[r.new] = r.value
    return out

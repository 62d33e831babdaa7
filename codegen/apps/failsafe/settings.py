"""Each battery's BATT*_ failsafe settings, read from a parameter set as ArduPilot names them.

``AP_BattMonitor.cpp`` ``var_info`` gives every monitor instance its own parameter group: battery 1
is ``BATT_``, batteries 2..9 are ``BATT2_``..``BATT9_``, 10..16 are ``BATTA_``..``BATTG_``. Defaults are those of
``AP_BattMonitor_Params.cpp`` (``CAPACITY`` 3300 mAh, ``LOW_TIMER`` 10 s, ``LOW_VOLT`` 10.5 V on
Copter and 0 elsewhere, everything else 0).
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from .vehicles import Vehicle

MAX_INSTANCES = 16  # AP_BATT_MONITOR_MAX_INSTANCES
FIELDS = ("MONITOR", "CAPACITY", "LOW_VOLT", "LOW_TIMER", "LOW_MAH", "CRT_VOLT", "CRT_MAH", "FS_LOW_ACT",
          "FS_CRT_ACT", "FS_VOLTSRC", "ARM_VOLT", "ARM_MAH")  # fmt: skip
MONITOR_VOLTAGE_ONLY = 3  # BATT_MONITOR 3: Analog Voltage Only (has_current() is false)
MONITOR_DISABLED = 0
VOLTSRC_RESTING = 1  # BATT_FS_VOLTSRC 1: Sag Compensated Voltage


def prefix(instance: int) -> str:
    """``BATT_`` for battery 1, ``BATT2_`` .. ``BATT9_``, ``BATTA_`` .. ``BATTG_`` for 10..16."""
    if not 1 <= instance <= MAX_INSTANCES:
        raise ValueError(f"expected a battery instance from 1 to {MAX_INSTANCES}, got {instance}")
    return "BATT_" if instance == 1 else f"BATT{_LETTERS[instance]}_"


_LETTERS = {n: str(n) if n < 10 else chr(ord("A") + n - 10) for n in range(2, MAX_INSTANCES + 1)}
_INSTANCE_OF = {letter: n for n, letter in _LETTERS.items()}
_NAME = re.compile(r"BATT([2-9A-G]?)_([A-Z0-9_]+)")


def split_name(name: str) -> tuple[int, str] | None:
    """``BATT2_LOW_VOLT`` -> (2, ``LOW_VOLT``); None for a name outside the BATT*_ groups."""
    m = _NAME.fullmatch(name)
    if m is None:
        return None
    return (_INSTANCE_OF[m.group(1)] if m.group(1) else 1), m.group(2)


def instances(values: Mapping[str, Any]) -> list[int]:
    """The batteries a parameter set configures (any BATT*_ parameter of theirs present), 1 always."""
    found = {1}
    for name in values:
        split = split_name(name)
        if split is not None and split[1] in FIELDS:
            found.add(split[0])
    return sorted(found)


def unprefixed(values: Mapping[str, Any], instance: int) -> dict[str, Any]:
    """One battery's parameters under battery 1's names (``BATT2_LOW_VOLT`` -> ``BATT_LOW_VOLT``)."""
    head = prefix(instance)
    return {"BATT_" + name[len(head) :]: value for name, value in values.items() if name.startswith(head)}


@dataclass(frozen=True)
class BatterySettings:
    instance: int  # 1-based, as ArduPilot prints it
    capacity_mah: float = 3300.0
    low_volt: float = 0.0
    low_timer_s: float = 10.0
    low_mah: float = 0.0
    crt_volt: float = 0.0
    crt_mah: float = 0.0
    low_action: int = 0
    crt_action: int = 0
    volt_source: int = 0
    monitor: int | None = None  # None: not in the file (the data decides whether it measures current)

    @property
    def enabled(self) -> bool:
        return self.monitor != MONITOR_DISABLED

    @classmethod
    def from_values(cls, values: Mapping[str, Any], instance: int, vehicle: Vehicle) -> BatterySettings:
        """From a parameter set (all batteries' names); absent parameters take ArduPilot's defaults."""
        head = prefix(instance)

        def get(field: str, default: float) -> float:
            name = head + field
            value = values.get(name, default)
            if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
                raise ValueError(f"{name}: expected a finite number, got {value!r}")
            return float(value)

        def code(field: str) -> int:
            value = get(field, 0)
            if not value.is_integer():
                raise ValueError(f"{head}{field}: expected an integer, got {value:g}")
            return int(value)

        monitor = code("MONITOR") if head + "MONITOR" in values else None
        return cls(
            instance=instance,
            capacity_mah=get("CAPACITY", 3300.0),
            low_volt=get("LOW_VOLT", vehicle.default_low_volt),
            low_timer_s=get("LOW_TIMER", 10.0),
            low_mah=get("LOW_MAH", 0.0),
            crt_volt=get("CRT_VOLT", 0.0),
            crt_mah=get("CRT_MAH", 0.0),
            low_action=code("FS_LOW_ACT"),
            crt_action=code("FS_CRT_ACT"),
            volt_source=code("FS_VOLTSRC"),
            monitor=monitor,
        )


def battery_settings(values: Mapping[str, Any], vehicle: Vehicle) -> dict[int, BatterySettings]:
    """Every battery's settings, by 1-based instance (ValueError names a parameter that is no number)."""
    return {i: BatterySettings.from_values(values, i, vehicle) for i in instances(values)}

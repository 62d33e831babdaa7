"""One battery reading in SI units, from any object or mapping that carries it, and a timed sample of one (what
every replay feeds the evaluator: :mod:`.stream` reads them from JSON Lines, :mod:`.logs` from flight logs)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class BatteryReading:
    """One battery measurement in SI-ish units; None (or a voltage of 0) means unknown."""

    voltage_v: float | None = None
    current_a: float | None = None
    consumed_mah: float | None = None
    remaining_mah: float | None = None


def _known(value: Any) -> float | None:
    if value is None or isinstance(value, bool) or not isinstance(value, int | float):
        return None
    return float(value) if math.isfinite(value) else None


def reading_of(state: Any) -> BatteryReading:
    """A :class:`BatteryReading` from any object or mapping carrying its attributes, or the shared
    battery concepts in SI (``pack_voltage`` V, ``current`` A, ``discharged`` C, ``state_of_charge``
    0..1 with ``full_capacity`` C) that the converters' canonical battery state uses."""
    if isinstance(state, BatteryReading):
        return state

    def get(name: str) -> float | None:
        value = state.get(name) if isinstance(state, Mapping) else getattr(state, name, None)
        return _known(value)

    volts = get("voltage_v")
    current = get("current_a")
    consumed = get("consumed_mah")
    remaining = get("remaining_mah")
    discharged, soc, full = get("discharged"), get("state_of_charge"), get("full_capacity")
    if consumed is None and discharged is not None:
        consumed = discharged / 3.6  # coulombs -> mAh
    if remaining is None and soc is not None and full is not None:
        remaining = soc * full / 3.6
    return BatteryReading(
        voltage_v=volts if volts is not None else get("pack_voltage"),
        current_a=current if current is not None else get("current"),
        consumed_mah=consumed,
        remaining_mah=remaining,
    )


@dataclass(frozen=True)
class Sample:
    line: int
    t: float
    armed: bool
    battery: BatteryReading
    message: str | None  # qualified name the battery came from (None: given in SI)
    data: Mapping[str, Any] | None
    extra: Mapping[str, Any]  # distance_to_home_m, travelled_m, home_set, position_fix
    instance: int = 1  # the battery, 1-based as ArduPilot prints it
    where: str = ""  # how to find it again: "line 12", "offset 4711"
    stamp_us: int | None = None  # the log's own clock (ULog/DataFlash µs since boot, tlog µs since the epoch)

    @property
    def place(self) -> str:
        return self.where or f"line {self.line}"

"""The battery failsafe with ArduPilot's semantics (``AP_BattMonitor::check_failsafes``), for replays.

Pure library code: no I/O. Feed :meth:`BatteryFailsafe.update` timed readings of any battery
instance (a :class:`BatteryReading`, or any object with the same attributes, such as a converter's
canonical battery state) and it returns the transitions as :class:`Event`\\ s.

As ``AP_BattMonitor`` does:
- every reading goes through its battery's monitor (:mod:`.monitor`: consumed charge, resistance
  estimate); the failsafe is checked only while armed;
- a battery's level only rises (``type <= state[i].failsafe`` is skipped), and never clears: not
  on recovery, not on disarming (only a reset of the remaining charge would clear it);
- a new level takes its battery's ``FS_LOW_ACT`` / ``FS_CRT_ACT``, maps it to its index in the
  vehicle's priority list (:mod:`.vehicles`), and runs it only if that index is at most the highest
  priority already run by any battery (``priority <= _highest_failsafe_priority``); the vehicle's
  handler then falls back as it can (``outcome``);
- the operator sees ``Battery 1 is low 10.40V used 2500 mAh``.

The seed's own choices are opt-in variants (``variants``): ``seed-critical`` (FR-DRAFT-2: "Trigger
immediately when voltage < BATT_CRT_VOLT (no hysteresis)", "CRITICAL overrides LOW action (higher
priority)") and ``distance`` (Phase 2's distance-aware trigger, :mod:`.distance`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from .distance import DistanceRule
from .levels import Level, mavlink_charge_state, uorb_warning
from .monitor import BatteryMonitor, Trigger
from .reading import BatteryReading, reading_of
from .settings import MAX_INSTANCES, VOLTSRC_RESTING, BatterySettings
from .vehicles import Situation, Vehicle

SEED_CRITICAL = "seed-critical"
DISTANCE = "distance"
VARIANTS = {
    SEED_CRITICAL: "seed FR-DRAFT-2: CRITICAL voltage at once (no BATT_LOW_TIMER) and its action always runs",
    DISTANCE: "seed Phase 2 (FR-DRAFT-5): LOW when the charge left no longer covers the way home x margin",
}
INITIAL_PRIORITY = 127  # INT8_MAX: AP_BattMonitor::init sets _highest_failsafe_priority to it

__all__ = ["BatteryFailsafe", "BatteryReading", "BatterySettings", "Event", "Level", "reading_of"]


@dataclass(frozen=True)
class Event:
    time: float
    battery: int  # 1-based, as ArduPilot prints it
    level: Level
    cause: str  # "voltage", "capacity" or "distance"
    value: float  # V for voltage; remaining mAh for capacity and distance
    threshold: float  # the parameter crossed (V / mAh), or the mAh needed to return
    action_code: int  # the FS_LOW_ACT / FS_CRT_ACT value
    action: str  # the vehicle's name for it
    executed: bool  # the priority rule let it run
    outcome: str  # what the vehicle does after the handler's fallbacks ("not run" when not executed)
    priority: int  # index in the vehicle's priority list
    voltage: float  # the raw voltage (what ArduPilot prints)
    consumed_mah: float
    voltage_source: str  # "raw" or "resting" (BATT_FS_VOLTSRC)
    text: str  # the operator text as the seed words it
    ardupilot_text: str  # the STATUSTEXT as AP_BattMonitor::check_failsafes sends it

    @property
    def uorb_warning(self) -> int:
        return uorb_warning(self.level)

    @property
    def mavlink_charge_state(self) -> int:
        return mavlink_charge_state(self.level)


def seed_text(level: Level, cause: str, value: float, threshold: float) -> str:
    """The seed's operator text (FR-DRAFT-1/2: "Battery LOW: {voltage}V", "Battery CRITICAL: {voltage}V")."""
    head = f"Battery {level.name}"
    if cause == "voltage":
        return f"{head}: {value:.1f}V"
    if cause == "distance":
        return f"{head}: {value:.0f}mAh left, {threshold:.0f}mAh needed to return"
    return f"{head}: {value:.0f}mAh"


def ardupilot_text(battery: int, level: Level, voltage: float, consumed_mah: float) -> str:
    """AP_BattMonitor::check_failsafes: "Battery %d is %s %.2fV used %.0f mAh"."""
    return f"Battery {battery} is {level.name.lower()} {voltage:.2f}V used {consumed_mah:.0f} mAh"


@dataclass
class BatteryFailsafe:
    """The evaluator over every battery of a vehicle. ``settings`` maps 1-based instances to their
    parameters; a reading of an instance without settings gets ArduPilot's defaults."""

    settings: Mapping[int, BatterySettings]
    vehicle: Vehicle
    situation: Situation = field(default_factory=Situation)
    variants: frozenset[str] = frozenset()
    distance_rule: DistanceRule = field(default_factory=DistanceRule)

    events: list[Event] = field(default_factory=list, init=False)
    highest_priority: int = field(default=INITIAL_PRIORITY, init=False)
    monitors: dict[int, BatteryMonitor] = field(default_factory=dict, init=False)
    _last_ms: int | None = field(default=None, init=False)
    _armed: bool = field(default=False, init=False)
    _terminated: bool = field(default=False, init=False)

    def __post_init__(self) -> None:
        unknown = set(self.variants) - set(VARIANTS)
        if unknown:
            raise ValueError(f"expected variants among {', '.join(VARIANTS)}, got {', '.join(sorted(unknown))}")

    @property
    def level(self) -> Level:
        """The highest level of any battery."""
        return max((m.failsafe for m in self.monitors.values()), default=Level.NONE)

    def monitor(self, instance: int) -> BatteryMonitor:
        if instance not in self.monitors:
            if not 1 <= instance <= MAX_INSTANCES:
                raise ValueError(f"expected a battery instance from 1 to {MAX_INSTANCES}, got {instance}")
            settings = self.settings.get(instance) or BatterySettings(instance, low_volt=self.vehicle.default_low_volt)
            self.monitors[instance] = BatteryMonitor(settings)
        return self.monitors[instance]

    def update(
        self,
        t: float,
        battery: Any,
        *,
        armed: bool,
        instance: int = 1,
        distance_to_home_m: float | None = None,
        travelled_m: float | None = None,
        home_set: bool | None = None,
        position_fix: bool | None = None,
    ) -> list[Event]:
        """One reading of battery ``instance`` at ``t`` seconds (never going back)."""
        if not math.isfinite(t):
            raise ValueError(f"expected a finite time, got {t}")
        now_ms = round(t * 1000)
        if self._last_ms is not None and now_ms < self._last_ms:
            raise ValueError(f"expected sample times that never go back, got {t} after {self._last_ms / 1000}")
        self._last_ms = now_ms
        reading = reading_of(battery)
        mon = self.monitor(instance)
        if not mon.settings.enabled:
            return []  # BATTn_MONITOR = 0: ArduPilot has no monitor for it
        mon.read(now_ms, reading.voltage_v, reading.current_a, reading.consumed_mah, reading.remaining_mah)
        if self._terminated:  # the failsafe disarmed the vehicle: silent until the stream agrees
            if armed:
                return []
            self._terminated = False
        if not armed:
            self._armed = False
            return []
        if not self._armed:
            self._armed = True
            self.distance_rule.rearm()
        situation = Situation(
            home_set=self.situation.home_set if home_set is None else home_set,
            position_fix=self.situation.position_fix if position_fix is None else position_fix,
            smart_rtl_ready=self.situation.smart_rtl_ready,
            quadplane=self.situation.quadplane,
            landing_sequence=self.situation.landing_sequence,
        )
        trigger = mon.update_failsafes(now_ms, critical_timer=SEED_CRITICAL not in self.variants)
        if DISTANCE in self.variants and mon.measures_current:
            self.distance_rule.learn(mon.consumed_mah, distance_to_home_m, travelled_m)
            if trigger is None or trigger.level < Level.LOW:
                needed = self.distance_rule.needed(mon.consumed_mah, distance_to_home_m)
                if needed is not None and mon.remaining_mah <= needed:
                    trigger = Trigger(Level.LOW, "distance", mon.remaining_mah, needed)
        if trigger is None or trigger.level <= mon.failsafe:
            return []
        event = self._fire(t, mon, trigger, situation)
        self.events.append(event)
        return [event]

    def fire(self, t: float, mon: BatteryMonitor, trigger: Trigger) -> Event:
        """An event of ``mon`` (its voltage and consumed charge as of ``t``) for ``trigger``, as :meth:`update`
        fires it, without the stream's extra fields (the columnar replay of :mod:`.columnar`)."""
        event = self._fire(t, mon, trigger, self.situation)
        self.events.append(event)
        return event

    def _fire(self, t: float, mon: BatteryMonitor, trigger: Trigger, situation: Situation) -> Event:
        s = mon.settings
        level = trigger.level
        mon.failsafe = level
        code = s.crt_action if level is Level.CRITICAL else s.low_action
        name = self.vehicle.actions("critical" if level is Level.CRITICAL else "low").get(code, f"unknown ({code})")
        priority = self.vehicle.priority(code)
        executed = priority <= self.highest_priority
        if SEED_CRITICAL in self.variants and level is Level.CRITICAL:
            executed = True  # FR-DRAFT-2: "CRITICAL overrides LOW action"
        outcome = "not run"
        if executed:
            self.highest_priority = priority
            outcome = self.vehicle.resolve(code, situation)
            if outcome == "disarm":
                self._terminated = True
        source = "resting" if s.volt_source == VOLTSRC_RESTING and trigger.cause == "voltage" else "raw"
        return Event(
            time=t,
            battery=s.instance,
            level=level,
            cause=trigger.cause,
            value=trigger.value,
            threshold=trigger.threshold,
            action_code=code,
            action=name,
            executed=executed,
            outcome=outcome,
            priority=priority,
            voltage=mon.voltage,
            consumed_mah=mon.consumed_mah,
            voltage_source=source,
            text=seed_text(level, trigger.cause, trigger.value, trigger.threshold),
            ardupilot_text=ardupilot_text(s.instance, level, mon.voltage, mon.consumed_mah),
        )


def make_failsafe(
    settings: Iterable[BatterySettings] | Mapping[int, BatterySettings],
    vehicle: Vehicle,
    *,
    situation: Situation | None = None,
    variants: Iterable[str] = (),
    distance_rule: DistanceRule | None = None,
) -> BatteryFailsafe:
    by_instance = dict(settings) if isinstance(settings, Mapping) else {s.instance: s for s in settings}
    return BatteryFailsafe(
        by_instance,
        vehicle,
        situation or Situation(),
        frozenset(variants),
        distance_rule or DistanceRule(),
    )

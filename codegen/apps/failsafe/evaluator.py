"""A two-stage (LOW, CRITICAL) battery failsafe evaluator with ArduPilot's BATT_* semantics.

Pure library code: no I/O. Feed it samples in SI units (a :class:`BatteryReading`, or any object
with the same attributes, such as a converter's canonical battery state) and it returns the
transitions as :class:`Event`\\ s.

Semantics (seed AN-00035 and the BATT_* parameter docs):
- CRITICAL at once when voltage < BATT_CRT_VOLT or remaining mAh < BATT_CRT_MAH.
- LOW when voltage < BATT_LOW_VOLT continuously for BATT_LOW_TIMER s, or remaining mAh < BATT_LOW_MAH,
  or (distance rule) the remaining charge no longer covers the way home times the safety margin.
- A threshold of 0 is disabled; a voltage of 0 / NaN / None is unknown and never triggers (and
  restarts the LOW timer); nothing triggers while disarmed.
- Levels only escalate while armed: a recovering voltage does not clear LOW (a manual mode change
  is needed), CRITICAL overrides LOW and never clears. Disarming clears the level (a new flight).
- Remaining mAh is BATT_CAPACITY minus the consumed charge (as ArduPilot computes it); consumed
  charge comes from the reading, else from integrating its current; else the reading's own
  remaining mAh.
- Actions fall back SmartRTL -> RTL -> Hold (RTL needs a home position and a position fix;
  SmartRTL also a recorded path); SmartRTL-or-Hold skips RTL; Terminate disarms.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from .levels import Level, mavlink_charge_state, uorb_warning

MAH_PER_AS = 1000.0 / 3600.0  # one ampere for one second, in mAh


class Action(enum.IntEnum):
    """BATT_FS_LOW_ACT / BATT_FS_CRT_ACT values (params.BATT.FS_LOW_ACT)."""

    NONE = 0
    HOLD = 1
    RTL = 2
    SMART_RTL = 3
    SMART_RTL_OR_HOLD = 4
    TERMINATE = 5


class Outcome(str, enum.Enum):
    """What the vehicle ends up doing once the fallback chain has run."""

    NONE = "none"
    HOLD = "hold"
    RTL = "rtl"
    SMART_RTL = "smart_rtl"
    DISARM = "disarm"


class Cause(str, enum.Enum):
    VOLTAGE = "voltage"
    CAPACITY = "capacity"
    DISTANCE = "distance"
    DISARMED = "disarmed"


# the schema's defaults (schemas/params/battery_failsafe.pdef.xml); a test keeps them in step
DEFAULTS: dict[str, float] = {
    "BATT_CAPACITY": 3300,
    "BATT_LOW_VOLT": 0.0,
    "BATT_LOW_TIMER": 10,
    "BATT_LOW_MAH": 0.0,
    "BATT_CRT_VOLT": 0.0,
    "BATT_CRT_MAH": 0.0,
    "BATT_FS_LOW_ACT": 0,
    "BATT_FS_CRT_ACT": 0,
}


@dataclass(frozen=True)
class FailsafeSettings:
    capacity_mah: float = DEFAULTS["BATT_CAPACITY"]
    low_volt: float = DEFAULTS["BATT_LOW_VOLT"]
    low_timer_s: float = DEFAULTS["BATT_LOW_TIMER"]
    low_mah: float = DEFAULTS["BATT_LOW_MAH"]
    crt_volt: float = DEFAULTS["BATT_CRT_VOLT"]
    crt_mah: float = DEFAULTS["BATT_CRT_MAH"]
    low_action: Action = Action.NONE
    crt_action: Action = Action.NONE

    @classmethod
    def from_values(cls, values: Mapping[str, Any]) -> FailsafeSettings:
        """From BATT_* names (a parameter file, or a generated ``BattParams.to_dict()``); others ignored."""

        def get(name: str) -> float:
            value = values.get(name, DEFAULTS[name])
            if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
                raise ValueError(f"{name}: expected a finite number, got {value!r}")
            return float(value)

        def action(name: str) -> Action:
            code = get(name)
            if not code.is_integer() or int(code) not in Action._value2member_map_:
                raise ValueError(f"{name}: expected an action 0..5, got {values.get(name)!r}")
            return Action(int(code))

        return cls(
            capacity_mah=get("BATT_CAPACITY"),
            low_volt=get("BATT_LOW_VOLT"),
            low_timer_s=get("BATT_LOW_TIMER"),
            low_mah=get("BATT_LOW_MAH"),
            crt_volt=get("BATT_CRT_VOLT"),
            crt_mah=get("BATT_CRT_MAH"),
            low_action=action("BATT_FS_LOW_ACT"),
            crt_action=action("BATT_FS_CRT_ACT"),
        )


@dataclass(frozen=True)
class BatteryReading:
    """One battery measurement in SI-ish units; None (or a voltage of 0) means unknown."""

    voltage_v: float | None = None
    current_a: float | None = None
    consumed_mah: float | None = None
    remaining_mah: float | None = None


@dataclass(frozen=True)
class Event:
    time: float
    level: Level
    cause: Cause
    value: float | None  # V for voltage, mAh for capacity and distance (remaining)
    threshold: float | None  # the parameter crossed (V / mAh), or the mAh needed to return
    action: Action  # as configured
    outcome: Outcome  # after the fallback chain
    text: str  # the operator message (STATUSTEXT)

    @property
    def uorb_warning(self) -> int:
        return uorb_warning(self.level)

    @property
    def mavlink_charge_state(self) -> int:
        return mavlink_charge_state(self.level)


def resolve_action(action: Action, *, home_set: bool, position_fix: bool, smart_rtl_ready: bool) -> Outcome:
    """The fallback chain: SmartRTL -> RTL -> Hold; SmartRTL-or-Hold skips RTL; Terminate disarms."""
    can_rtl = home_set and position_fix
    can_smart = can_rtl and smart_rtl_ready
    if action is Action.NONE:
        return Outcome.NONE
    if action is Action.TERMINATE:
        return Outcome.DISARM
    if action in (Action.SMART_RTL, Action.SMART_RTL_OR_HOLD) and can_smart:
        return Outcome.SMART_RTL
    if action in (Action.SMART_RTL, Action.RTL) and can_rtl:
        return Outcome.RTL
    return Outcome.HOLD


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
    return BatteryReading(
        voltage_v=volts if volts is not None else get("pack_voltage"),
        current_a=current if current is not None else get("current"),
        consumed_mah=consumed if consumed is not None else None if discharged is None else discharged / 3.6,
        remaining_mah=remaining
        if remaining is not None
        else None
        if soc is None or full is None
        else soc * full / 3.6,  # coulombs -> mAh
    )


@dataclass
class _Trip:
    """What the distance rule learns between arming and now."""

    integrated_mah: float = 0.0
    consumed_at_arm: float | None = None
    travelled_m: float = 0.0
    last_distance: float | None = None


@dataclass
class BatteryFailsafe:
    """The evaluator. ``update`` takes one sample and returns the transitions it caused.

    Options: ``home_set`` / ``position_fix`` (defaults for samples that do not say), ``smart_rtl_ready``
    (a SmartRTL path is recorded), ``margin`` (safety factor of the distance rule), ``reserve_mah``
    (charge to arrive home with), ``consumption_mah_per_m`` (used until enough travel is seen to learn
    it), ``learn_after_m`` (travel needed before the learned rate is trusted).
    """

    params: FailsafeSettings
    home_set: bool = True
    position_fix: bool = True
    smart_rtl_ready: bool = True
    margin: float = 1.3
    reserve_mah: float = 0.0
    consumption_mah_per_m: float | None = None
    learn_after_m: float = 20.0
    distance_rule: bool = True

    level: Level = field(default=Level.NONE, init=False)
    events: list[Event] = field(default_factory=list, init=False)
    _last_t: float | None = field(default=None, init=False)
    _low_since: float | None = field(default=None, init=False)
    _armed: bool = field(default=False, init=False)
    _terminated: bool = field(default=False, init=False)
    _last_current: float | None = field(default=None, init=False)
    _trip: _Trip = field(default_factory=_Trip, init=False)

    def update(
        self,
        t: float,
        battery: Any,
        *,
        armed: bool,
        distance_to_home_m: float | None = None,
        travelled_m: float | None = None,
        home_set: bool | None = None,
        position_fix: bool | None = None,
    ) -> list[Event]:
        if not math.isfinite(t) or (self._last_t is not None and t < self._last_t):
            raise ValueError(f"expected sample times that never go back, got {t} after {self._last_t}")
        reading = reading_of(battery)
        dt = 0.0 if self._last_t is None else t - self._last_t
        self._last_t = t
        out: list[Event] = []
        if self._terminated:  # the failsafe disarmed the vehicle: silent until the stream agrees
            if armed:
                return out
            self._terminated = self._armed = False
            self.level = Level.NONE
        if not armed:
            if self._armed and self.level is not Level.NONE:
                out.append(self._event(t, Level.NONE, Cause.DISARMED, None, None, Action.NONE, Outcome.NONE))
            self._armed = False
            self.level = Level.NONE
            self._low_since = None
            self._last_current = reading.current_a
            self.events.extend(out)
            return out
        if not self._armed:
            self._armed = True
            self._trip = _Trip()
            dt = 0.0
        consumed = self._consumed(reading, dt)
        remaining = self._remaining(reading, consumed)
        self._learn(consumed, distance_to_home_m, travelled_m)
        home = self.home_set if home_set is None else home_set
        fix = self.position_fix if position_fix is None else position_fix
        rate = self.consumption_rate(consumed)
        out.extend(self._evaluate(t, reading, remaining, rate, distance_to_home_m, home, fix))
        self.events.extend(out)
        return out

    # -- measurements

    def _consumed(self, reading: BatteryReading, dt: float) -> float | None:
        trip = self._trip
        if self._last_current is not None and dt > 0:
            trip.integrated_mah += self._last_current * dt * MAH_PER_AS
        self._last_current = reading.current_a
        if reading.consumed_mah is not None:
            return reading.consumed_mah
        if reading.current_a is not None or trip.integrated_mah > 0:
            return trip.integrated_mah  # a current sensor: integrate it (since arming)
        return None

    def _remaining(self, reading: BatteryReading, consumed: float | None) -> float | None:
        if consumed is not None and consumed > 0 and self.params.capacity_mah > 0:
            return self.params.capacity_mah - consumed
        return reading.remaining_mah

    def _learn(self, consumed: float | None, distance: float | None, travelled: float | None) -> None:
        trip = self._trip
        if consumed is not None and trip.consumed_at_arm is None:
            trip.consumed_at_arm = consumed
        if travelled is not None:
            trip.travelled_m = travelled
        elif distance is not None:
            if trip.last_distance is not None:
                trip.travelled_m += abs(distance - trip.last_distance)
            trip.last_distance = distance

    def consumption_rate(self, consumed: float | None) -> float | None:
        """mAh per metre: learned since arming once enough travel is seen, else the configured one."""
        trip = self._trip
        if consumed is not None and trip.consumed_at_arm is not None and trip.travelled_m >= self.learn_after_m:
            return max(consumed - trip.consumed_at_arm, 0.0) / trip.travelled_m
        return self.consumption_mah_per_m

    # -- the two stages

    def _evaluate(
        self,
        t: float,
        r: BatteryReading,
        remaining: float | None,
        rate: float | None,
        distance: float | None,
        home: bool,
        fix: bool,
    ) -> list[Event]:
        p = self.params
        volts = r.voltage_v if r.voltage_v is not None and r.voltage_v > 0 else None
        if volts is None or not (p.low_volt > 0 and volts < p.low_volt):
            self._low_since = None
        elif self._low_since is None:
            self._low_since = t
        if self.level is Level.CRITICAL:
            return []

        def fire(level: Level, cause: Cause, value: float, threshold: float) -> list[Event]:
            action = p.crt_action if level is Level.CRITICAL else p.low_action
            outcome = resolve_action(action, home_set=home, position_fix=fix, smart_rtl_ready=self.smart_rtl_ready)
            self.level = level
            if outcome is Outcome.DISARM:
                self._terminated = True
            return [self._event(t, level, cause, value, threshold, action, outcome)]

        if volts is not None and p.crt_volt > 0 and volts < p.crt_volt:
            return fire(Level.CRITICAL, Cause.VOLTAGE, volts, p.crt_volt)
        if remaining is not None and p.crt_mah > 0 and remaining < p.crt_mah:
            return fire(Level.CRITICAL, Cause.CAPACITY, remaining, p.crt_mah)
        if self.level is Level.LOW:
            return []
        if volts is not None and self._low_since is not None and t - self._low_since >= p.low_timer_s:
            return fire(Level.LOW, Cause.VOLTAGE, volts, p.low_volt)
        if remaining is not None and p.low_mah > 0 and remaining < p.low_mah:
            return fire(Level.LOW, Cause.CAPACITY, remaining, p.low_mah)
        if self.distance_rule and remaining is not None and distance is not None and rate is not None:
            needed = distance * rate * self.margin + self.reserve_mah
            if remaining <= needed:
                return fire(Level.LOW, Cause.DISTANCE, remaining, needed)
        return []

    def _event(
        self,
        t: float,
        level: Level,
        cause: Cause,
        value: float | None,
        threshold: float | None,
        action: Action,
        outcome: Outcome,
    ) -> Event:
        return Event(t, level, cause, value, threshold, action, outcome, operator_text(level, cause, value, threshold))


def operator_text(level: Level, cause: Cause, value: float | None, threshold: float | None) -> str:
    """The STATUSTEXT an operator sees: ``Battery LOW: 10.4V``, ``Battery CRITICAL: 250mAh``."""
    if cause is Cause.DISARMED:
        return "Battery failsafe cleared: disarmed"
    head = f"Battery {level.name}"
    if value is None:
        return head
    if cause is Cause.VOLTAGE:
        return f"{head}: {value:.1f}V"
    if cause is Cause.DISTANCE and threshold is not None:
        return f"{head}: {value:.0f}mAh left, {threshold:.0f}mAh needed to return"
    return f"{head}: {value:.0f}mAh"

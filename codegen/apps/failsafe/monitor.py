"""One battery monitor as ArduPilot's ``AP_BattMonitor_Backend`` keeps it, restated for replays.

- :class:`ResistanceEstimator` restates ``update_resistance_estimate`` (run on every reading, armed
  or not): the pack's internal resistance from how the voltage falls as the current rises against
  low-pass filtered references (time constants ``AP_BATT_MONITOR_RES_EST_TC_1`` = 0.5 s and
  ``_TC_2`` = 0.1), capped by the largest drop seen from the highest voltage; the resting voltage
  is ``V + I * R``, and ``voltage_resting_estimate`` is never below the raw voltage.
- :class:`BatteryMonitor` keeps the consumed charge (the reading's own, else the current
  integrated as the analog backend does: the new current times the interval, intervals of 2 s and
  more skipped) and restates ``check_failsafe_types`` and ``update_failsafes``: the voltage in use is
  the raw one or, with ``BATT_FS_VOLTSRC`` = 1, the resting estimate; a voltage below
  ``BATT_CRT_VOLT`` or ``BATT_LOW_VOLT`` starts a timer and counts only once ``now - start >
  BATT_LOW_TIMER`` (strictly), so ``BATT_LOW_TIMER`` = 0 disables both voltage failsafes; the
  remaining charge ``BATT_CAPACITY - consumed`` counts at once, and only when the monitor
  measures current. The order is CRITICAL voltage, CRITICAL capacity, LOW voltage, LOW capacity.

Times are whole milliseconds, as ``AP_HAL::millis()``. ArduPilot marks "no timer" with a start of 0
ms; here it is None, so a replay starting at t = 0 is not delayed by one reading.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from .levels import Level
from .settings import MONITOR_VOLTAGE_ONLY, VOLTSRC_RESTING, BatterySettings

RES_EST_TC_1 = 0.5  # AP_BattMonitor.h AP_BATT_MONITOR_RES_EST_TC_1
RES_EST_TC_2 = 0.1  # AP_BATT_MONITOR_RES_EST_TC_2
FLT_EPSILON = 1.1920929e-07  # is_zero() / is_positive() in AP_Math
MAX_INTEGRATION_MS = 2000  # AP_BattMonitor_Analog::read skips longer gaps
MAH_PER_AMP_MS = 1.0 / 3600.0  # 1 A for 1 ms in mAh


@dataclass
class ResistanceEstimator:
    resistance: float = 0.0
    resting_voltage: float = 0.0
    voltage_filt: float = 0.0
    current_filt: float = 0.0
    current_max: float = 0.0
    voltage_ref: float = 0.0
    current_ref: float = 0.0
    timer_ms: int = 0

    def update(self, now_ms: int, voltage: float, current: float | None) -> None:
        if current is None or current < FLT_EPSILON:
            return
        self.current_max = max(self.current_max, current)
        delta = current - self.current_filt
        if abs(delta) < FLT_EPSILON:
            return
        if voltage > self.voltage_ref:
            self.voltage_ref, self.current_ref = voltage, current
        interval = (now_ms - self.timer_ms) / 1000.0
        self.timer_ms = now_ms
        filt_alpha = min(max(interval / (interval + RES_EST_TC_1), 0.0), 0.5)
        resistance_alpha = min(1.0, RES_EST_TC_2 * abs((current - self.current_filt) / self.current_max))
        estimate = -(voltage - self.voltage_filt) / delta
        if estimate >= FLT_EPSILON:
            self.resistance = self.resistance * (1 - resistance_alpha) + estimate * resistance_alpha
        if self.voltage_ref > voltage and current > self.current_ref:
            self.resistance = min(self.resistance, (self.voltage_ref - voltage) / (current - self.current_ref))
        self.voltage_filt = self.voltage_filt * (1 - filt_alpha) + voltage * filt_alpha
        self.current_filt = self.current_filt * (1 - filt_alpha) + current * filt_alpha
        self.resting_voltage = voltage + current * self.resistance

    def resting(self, voltage: float) -> float:
        """voltage_resting_estimate(): never below the raw voltage."""
        return max(voltage, self.resting_voltage)


@dataclass(frozen=True)
class Trigger:
    """What update_failsafes found: the level, which check, the value compared and its threshold."""

    level: Level
    cause: str  # "voltage" or "capacity"
    value: float
    threshold: float


@dataclass
class BatteryMonitor:
    settings: BatterySettings
    voltage: float = 0.0  # 0: unknown, as ArduPilot's state.voltage
    current: float | None = None
    consumed_mah: float = 0.0
    measures_current: bool = False
    failsafe: Level = Level.NONE  # state[i].failsafe: only ever raised
    low_start_ms: int | None = None
    critical_start_ms: int | None = None
    last_ms: int | None = None
    estimator: ResistanceEstimator = field(default_factory=ResistanceEstimator)

    def read(
        self, now_ms: int, voltage: float | None, current: float | None, consumed: float | None, remaining: float | None
    ) -> None:
        """A new reading (AP_BattMonitor::read: the backend's read, then the resistance estimate)."""
        s = self.settings
        self.voltage = voltage if voltage is not None and math.isfinite(voltage) and voltage > 0 else 0.0
        self.measures_current = s.monitor != MONITOR_VOLTAGE_ONLY and (
            current is not None or consumed is not None or remaining is not None
        )
        self.current = current if s.monitor != MONITOR_VOLTAGE_ONLY else None
        if consumed is not None:
            self.consumed_mah = consumed
        elif remaining is not None and s.capacity_mah > 0:
            self.consumed_mah = s.capacity_mah - remaining
        elif self.current is not None and self.last_ms is not None:
            dt = now_ms - self.last_ms
            if 0 < dt < MAX_INTEGRATION_MS:
                self.consumed_mah += self.current * dt * MAH_PER_AMP_MS
        self.last_ms = now_ms
        if self.measures_current:
            self.estimator.update(now_ms, self.voltage, self.current)

    @property
    def remaining_mah(self) -> float:
        return self.settings.capacity_mah - self.consumed_mah

    def voltage_used(self) -> float:
        """check_failsafe_types: the raw voltage, or the resting estimate with BATT_FS_VOLTSRC = 1."""
        if self.settings.volt_source == VOLTSRC_RESTING:
            return self.estimator.resting(self.voltage)
        return self.voltage

    def update_failsafes(self, now_ms: int, *, critical_timer: bool = True) -> Trigger | None:
        """The level the readings call for now (None: none). ``critical_timer`` False is the seed's
        FR-DRAFT-2 variant: CRITICAL voltage at once, without BATT_LOW_TIMER."""
        s = self.settings
        volts = self.voltage_used()
        critical_voltage = volts > 0 and s.crt_volt > 0 and volts < s.crt_volt
        low_voltage = volts > 0 and s.low_volt > 0 and volts < s.low_volt
        remaining = self.remaining_mah
        critical_capacity = self.measures_current and s.crt_mah > 0 and remaining < s.crt_mah
        low_capacity = self.measures_current and s.low_mah > 0 and remaining < s.low_mah
        timeout_ms = round(s.low_timer_s * 1000)

        if critical_voltage:
            if not critical_timer:
                return Trigger(Level.CRITICAL, "voltage", volts, s.crt_volt)
            if self.critical_start_ms is None:
                self.critical_start_ms = now_ms
            elif timeout_ms > 0 and now_ms - self.critical_start_ms > timeout_ms:
                return Trigger(Level.CRITICAL, "voltage", volts, s.crt_volt)
        else:
            self.critical_start_ms = None
        if critical_capacity:
            return Trigger(Level.CRITICAL, "capacity", remaining, s.crt_mah)
        if low_voltage:
            if self.low_start_ms is None:
                self.low_start_ms = now_ms
            elif timeout_ms > 0 and now_ms - self.low_start_ms > timeout_ms:
                return Trigger(Level.LOW, "voltage", volts, s.low_volt)
        else:
            self.low_start_ms = None
        if low_capacity:
            return Trigger(Level.LOW, "capacity", remaining, s.low_mah)
        return None

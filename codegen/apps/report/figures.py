"""The figures people compute by hand from a flight's battery data.

Charge used comes from the battery's own discharged counter where it reports one (the fuel gauge or the
autopilot's integrator), else from integrating the current (trapezoids); energy from integrating V·I. The
internal resistance is estimated from load steps (:mod:`codegen.apps.load_steps`, the definition the fleet views
share): consecutive samples at most 2 s apart whose current changes by at least 20 % of the flight's peak current
(and 1 A) give R = -ΔV/ΔI; the median of those steps is reported. The voltage sag per amp is the least-squares
slope of the voltage's sample-to-sample changes against the current's, over the whole flight: it uses every
change of load, small ones too, so it is the figure to compare between flights of one pack, while the load-step
median is the better estimate of the pack's resistance when a log is noisy.
"""

from __future__ import annotations

import statistics
from collections.abc import Sequence
from dataclasses import dataclass

from ..load_steps import STEP_MAX_DT_S, step_resistances
from .series import BatterySeries

STEP_MAX_DT = STEP_MAX_DT_S


@dataclass(frozen=True)
class Figures:
    duration_s: float
    samples: int
    charge_used_mah: float | None
    energy_used_wh: float | None
    average_power_w: float | None
    peak_power_w: float | None
    peak_current_a: float | None
    min_pack_voltage_v: float | None
    min_cell_voltage_v: float | None
    max_cell_imbalance_v: float | None
    max_temperature_c: float | None
    sag_per_amp_v_per_a: float | None
    internal_resistance_ohm: float | None
    load_steps: int
    time_below_s: dict[str, float]  # threshold name -> seconds spent below it

    def rows(self) -> list[tuple[str, str]]:
        """The figures as (label, text) rows for the page."""

        def num(value: float | None, unit: str, digits: int = 2) -> str:
            return "unknown" if value is None else f"{value:.{digits}f} {unit}"

        out = [
            ("duration", num(self.duration_s, "s", 1)),
            ("samples", str(self.samples)),
            ("charge used", num(self.charge_used_mah, "mAh", 0)),
            ("energy used", num(self.energy_used_wh, "Wh", 2)),
            ("average power", num(self.average_power_w, "W", 1)),
            ("peak power", num(self.peak_power_w, "W", 1)),
            ("peak current", num(self.peak_current_a, "A", 1)),
            ("minimum pack voltage", num(self.min_pack_voltage_v, "V", 2)),
            ("minimum cell voltage", num(self.min_cell_voltage_v, "V", 3)),
            (
                "max cell imbalance",
                num(None if self.max_cell_imbalance_v is None else self.max_cell_imbalance_v * 1000, "mV", 0),
            ),
            ("max temperature", num(self.max_temperature_c, "°C", 1)),
            (
                "voltage sag per amp",
                num(None if self.sag_per_amp_v_per_a is None else self.sag_per_amp_v_per_a * 1000, "mV/A", 1),
            ),
            (
                "internal resistance (load steps)",
                num(None if self.internal_resistance_ohm is None else self.internal_resistance_ohm * 1000, "mΩ", 1)
                + (f" from {self.load_steps} steps" if self.load_steps else ""),
            ),
        ]
        out += [(f"time below {name}", num(s, "s", 1)) for name, s in self.time_below_s.items()]
        return out


def _known(values: Sequence[float | None]) -> list[float]:
    return [v for v in values if v is not None]


def integrate(t: Sequence[float], values: Sequence[float | None]) -> float | None:
    """Trapezoid integral over the intervals whose two ends are known."""
    total, used = 0.0, False
    for k in range(1, len(t)):
        a, b = values[k - 1], values[k]
        if a is not None and b is not None:
            total += (a + b) / 2 * (t[k] - t[k - 1])
            used = True
    return total if used else None


def _charge_used(s: BatterySeries) -> float | None:
    counter = _known(s.discharged)
    if len(counter) >= 2 and max(counter) > 0:
        return counter[-1] - counter[0]
    amp_seconds = integrate(s.t, s.current)
    return None if amp_seconds is None else amp_seconds / 3.6


def _steps(s: BatterySeries) -> list[float]:
    return step_resistances(s.t, s.pack_voltage, s.current)


def _sag(s: BatterySeries) -> float | None:
    """-dV/dI as the least-squares slope through the origin of the sample-to-sample changes (ΔV on ΔI, samples
    at most STEP_MAX_DT apart): every change of load counts, small ones too, and the slow decline of the discharge
    adds little to ΔV between neighbours and nothing correlated with ΔI."""
    num = den = 0.0
    for k in range(1, len(s.t)):
        v0, v1, i0, i1 = s.pack_voltage[k - 1], s.pack_voltage[k], s.current[k - 1], s.current[k]
        if v0 is None or v1 is None or i0 is None or i1 is None or s.t[k] - s.t[k - 1] > STEP_MAX_DT:
            continue
        num += (i1 - i0) * (v1 - v0)
        den += (i1 - i0) ** 2
    return -num / den if den > 1e-9 else None


def _time_below(s: BatterySeries, threshold: float) -> float:
    total = 0.0
    for k in range(1, len(s.t)):
        v = s.pack_voltage[k - 1]
        if v is not None and v < threshold:
            total += s.t[k] - s.t[k - 1]
    return total


def compute(s: BatterySeries, thresholds: dict[str, float] | None = None) -> Figures:
    """The figures of one battery; ``thresholds`` (name -> volts, e.g. BATT_LOW_VOLT) for the time below each."""
    power = s.power
    currents = _known(s.current)
    steps = _steps(s)
    energy = integrate(s.t, power)
    duration = s.t[-1] - s.t[0] if len(s.t) > 1 else 0.0
    cells = [min(c) for c in s.cells if c]
    imbalance = _known(s.imbalance)
    temps = _known(s.temperature)
    volts = _known(s.pack_voltage)
    known_power = _known(power)
    return Figures(
        duration_s=duration,
        samples=len(s.t),
        charge_used_mah=_charge_used(s),
        energy_used_wh=None if energy is None else energy / 3600.0,
        average_power_w=energy / duration if energy is not None and duration > 0 else None,
        peak_power_w=max(known_power) if known_power else None,
        peak_current_a=max(currents) if currents else None,
        min_pack_voltage_v=min(volts) if volts else None,
        min_cell_voltage_v=min(cells) if cells else None,
        max_cell_imbalance_v=max(imbalance) if imbalance else None,
        max_temperature_c=max(temps) if temps else None,
        sag_per_amp_v_per_a=_sag(s),
        internal_resistance_ohm=statistics.median(steps) if steps else None,
        load_steps=len(steps),
        time_below_s={name: _time_below(s, v) for name, v in (thresholds or {}).items() if v > 0},
    )

"""The figures people compute by hand from a flight's battery data.

The flight's own figures -- records, its first and last time, armed time, minimum and maximum pack voltage, peak
current, charge and energy used -- are :mod:`codegen.apps.battery.figures`, the one definition the fleet views
share: charge and energy from the battery's own counter where it keeps one, else the trapezoid integral of the
current and of V·I. The
internal resistance is estimated from load steps (:mod:`codegen.apps.battery.load_steps`, the definition the fleet views
share): consecutive samples at most 2 s apart whose current changes by at least 20 % of the flight's peak current
(and 1 A) give R = -ΔV/ΔI; the median of those steps is reported. The voltage sag per amp is the least-squares
slope of the voltage's sample-to-sample changes against the current's, over the whole flight: it uses every
change of load, small ones too, so it is the figure to compare between flights of one pack, while the load-step
median is the better estimate of the pack's resistance when a log is noisy.
"""

from __future__ import annotations

import math
import statistics
from dataclasses import dataclass

import numpy as np

from ..battery.columns import NDArray
from ..battery.figures import FlightFigures
from ..battery.load_steps import neighbour_changes, step_resistances
from .series import BatterySeries


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
    flight: FlightFigures  # in SI, as the fleet views have them

    def rows(self, per_cell: bool = True) -> list[tuple[str, str]]:
        """The figures as (label, text) rows for the page (``per_cell`` False: the log's cells are no measurement,
        said instead of their figures)."""

        def num(value: float | None, unit: str, digits: int = 2) -> str:
            return "unknown" if value is None else f"{shown(value, digits)} {unit}"

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
        if not per_cell:
            out = [(label, NO_CELLS if "cell" in label else text) for label, text in out]
        out += [(f"time below {name}", num(s, "s", 1)) for name, s in self.time_below_s.items()]
        return out


NO_CELLS = "no per-cell data"


def shown(value: float, digits: int) -> str:
    """A figure with the precision it carries: ``digits`` decimals, more for a small value that would show as 0 or
    with one significant digit (0.39 mAh, not 0 mAh)."""
    if value == 0 or value != value or math.isinf(value):
        return f"{value + 0.0:.{digits}f}"  # + 0.0: no "-0.0"
    return f"{value:.{max(digits, 1 - math.floor(math.log10(abs(value))))}f}"


def _max(values: NDArray) -> float | None:
    known = values[~np.isnan(values)]
    return float(known.max()) if len(known) else None


def _min(values: NDArray) -> float | None:
    known = values[~np.isnan(values)]
    return float(known.min()) if len(known) else None


def _steps(s: BatterySeries) -> list[float]:
    return step_resistances(s.t, s.pack_voltage, s.current)


def _sag(s: BatterySeries) -> float | None:
    """-dV/dI as the least-squares slope through the origin of the sample-to-sample changes (ΔV on ΔI, samples
    at most STEP_MAX_DT_S apart): every change of load counts, small ones too, and the slow decline of the discharge
    adds little to ΔV between neighbours and nothing correlated with ΔI."""
    dv, di = neighbour_changes(s.t, s.pack_voltage, s.current)
    num = sum((di * dv).tolist())  # summed in time order, as a person's loop would
    den = sum((di * di).tolist())
    return -num / den if den > 1e-9 else None


def _time_below(s: BatterySeries, threshold: float) -> float:
    dt = np.diff(s.t)
    with np.errstate(invalid="ignore"):
        below = s.pack_voltage[:-1] < threshold
    return float(sum(dt[below].tolist()))


def compute(s: BatterySeries, thresholds: dict[str, float] | None = None) -> Figures:
    """The figures of one battery; ``thresholds`` (name -> volts, e.g. BATT_LOW_VOLT) for the time below each."""
    flight = s.flight()
    steps = _steps(s)
    energy = flight.energy_used
    duration = flight.duration_s
    return Figures(
        duration_s=duration,
        samples=len(s.t),
        charge_used_mah=None if flight.charge_used is None else flight.charge_used / 3.6,
        energy_used_wh=None if energy is None else energy / 3600.0,
        average_power_w=energy / duration if energy is not None and duration > 0 else None,
        peak_power_w=_max(s.power),
        peak_current_a=flight.max_current,
        min_pack_voltage_v=flight.min_voltage,
        min_cell_voltage_v=_min(s.cells),
        max_cell_imbalance_v=_max(s.imbalance),
        max_temperature_c=_max(s.temperature),
        sag_per_amp_v_per_a=_sag(s),
        internal_resistance_ohm=statistics.median(steps) if steps else None,
        load_steps=len(steps),
        time_below_s={name: _time_below(s, v) for name, v in (thresholds or {}).items() if v > 0},
        flight=flight,
    )

"""The failsafe replay of a log's samples over whole columns, with exactly the per-sample evaluator's events.

:meth:`.evaluator.BatteryFailsafe.update` stays the oracle; this is the same state machine restated over numpy
columns of a :class:`.logs.SampleTable`, per battery:

- the monitor's reading (``BatteryMonitor.read``): the voltage (0 where unknown), whether the monitor measures
  current, and the consumed charge: the log's own where it gives one, else the current integrated as the
  analog backend does, summed in sample order (``np.cumsum`` adds one after the other, as the loop does; a
  sample that adds nothing adds -0.0, IEEE's exact identity);
- the resting-voltage estimate (``BATT_FS_VOLTSRC`` = 1) is a nonlinear recurrence: it stays per sample, the
  evaluator's own :class:`.monitor.ResistanceEstimator` run on the samples it would change on;
- the four conditions of ``update_failsafes`` over the checked samples (armed, the monitor enabled, not after a
  failsafe disarmed the vehicle), the two timers as runs of a condition over those samples (a run's start is
  its first sample; it fires at its first later sample more than ``BATT_LOW_TIMER`` after);
- a battery's level only rises, so its events are the first sample calling for more than its level. A CRITICAL
  trigger leaves nothing more to happen for its battery, so the early returns of ``update_failsafes`` (which skip
  the LOW timer) change nothing before it.

Events are fired in time order through the evaluator itself (:meth:`~.evaluator.BatteryFailsafe.fire`: the
priority rule across batteries, the vehicle's fallbacks, the texts). An event whose outcome disarms silences every
battery until the next disarmed sample, as the evaluator does; the candidates are then found again. A battery has
at most two events, so that loop is short.

Streams the columns cannot restate exactly go through the per-sample evaluator: the ``distance`` variant (it reads
the sample's extra fields), a time that is not finite or a battery outside 1..16 (the evaluator's errors).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...errors import BattgenError
from .evaluator import DISTANCE, SEED_CRITICAL, BatteryFailsafe, Event
from .levels import Level
from .monitor import FLT_EPSILON, MAH_PER_AMP_MS, MAX_INTEGRATION_MS, ResistanceEstimator, Trigger
from .reading import Sample
from .settings import MAX_INSTANCES, MONITOR_VOLTAGE_ONLY, VOLTSRC_RESTING, BatterySettings

if TYPE_CHECKING:  # the flight logs' readers and the IR: a JSON Lines stream's replay needs neither
    from ..battery.columns import NDArray
    from .logs import SampleTable


@dataclass
class _Battery:
    """One battery's columns over its samples (``rows``: their indices in the log's sample order)."""

    settings: BatterySettings
    rows: NDArray
    now: NDArray  # ms
    voltage: NDArray  # the raw voltage, 0 where unknown
    used: NDArray  # the voltage the failsafe compares (raw or resting)
    consumed: NDArray
    cv: NDArray
    lv: NDArray
    cc: NDArray
    lc: NDArray


def replay_table(
    failsafe: BatteryFailsafe, table: SampleTable, name: str | None = None
) -> tuple[list[tuple[Event, Sample]], dict[int, int]]:
    """Every event of the table's samples with the sample that caused it, and the samples read per battery
    (1-based). ``failsafe`` must be fresh; it ends holding the events and each battery's level. Errors are
    the per-sample replay's, named ``name: place: ...`` (``place: ...`` without a name)."""
    t, battery, volts, amps, mah, armed, where = table.sorted_columns()
    instance = battery + 1
    counts = {int(i): int(c) for i, c in zip(*np.unique(instance, return_counts=True), strict=True)}
    at = table.sample_at
    out = replay_columns(failsafe, t, instance, volts, amps, mah, armed == 1.0, lambda row: at(int(where[row])))
    return (_per_sample(failsafe, table, name) if out is None else out), counts


def replay_columns(
    failsafe: BatteryFailsafe,
    t: NDArray,
    instance: NDArray,
    volts: NDArray,
    amps: NDArray,
    mah: NDArray,
    armed_b: NDArray,
    sample_at: Callable[[int], Sample],
) -> list[tuple[Event, Sample]] | None:
    """The events of samples given as columns in the order the evaluator reads them (``sample_at``: the sample of a
    row, for the events' places), or None where the columns cannot restate the evaluator exactly (the caller replays
    sample by sample, with the evaluator's errors): the distance variant, a used evaluator, a time that is not
    finite or goes back, a battery outside 1..16."""
    exact = DISTANCE not in failsafe.variants and not failsafe.monitors and not failsafe.events
    if not exact or not np.isfinite(t).all():
        return None
    if len(instance) and (instance.min() < 1 or instance.max() > MAX_INSTANCES):
        return None
    now_ms = t * 1000.0
    now = np.rint(now_ms, out=now_ms).astype(np.int64)
    if len(now) and (np.diff(now) < 0).any():
        return None
    n = len(t)
    batteries: list[_Battery] = []
    enabled = np.zeros(n, bool)
    for inst, count in _instances(instance):
        mon = failsafe.monitor(int(inst))
        if not mon.settings.enabled:
            continue
        if count == n:  # one battery: its columns are the stream's, not copies of them
            enabled[:] = True
            batteries.append(_columns(mon.settings, np.arange(n), now, volts, amps, mah))
        else:
            rows = np.flatnonzero(instance == inst)
            enabled[rows] = True
            batteries.append(_columns(mon.settings, rows, now[rows], volts[rows], amps[rows], mah[rows]))
    timer = SEED_CRITICAL not in failsafe.variants
    checked = enabled & armed_b
    out: list[tuple[Event, Sample]] = []
    while True:
        found: tuple[int, _Battery, Trigger] | None = None
        for b in batteries:
            mon = failsafe.monitors[b.settings.instance]
            if mon.failsafe is Level.CRITICAL:
                continue
            hit = _next_event(b, checked if len(b.rows) == n else checked[b.rows], mon.failsafe, timer)
            if hit is not None and (found is None or b.rows[hit[0]] < found[0]):
                found = (int(b.rows[hit[0]]), b, hit[1])
        if found is None:
            break
        row, b, trigger = found
        k = int(np.searchsorted(b.rows, row))
        mon = failsafe.monitors[b.settings.instance]
        mon.voltage, mon.consumed_mah = float(b.voltage[k]), float(b.consumed[k])
        event = failsafe.fire(float(t[row]), mon, trigger)
        out.append((event, sample_at(row)))
        if event.outcome == "disarm":  # silent until a disarmed sample of an enabled battery
            later = np.flatnonzero(enabled[row + 1 :] & ~armed_b[row + 1 :])
            end = row + 1 + int(later[0]) if len(later) else len(t)
            checked[row + 1 : end] = False
    return out


def _instances(instance: NDArray) -> list[tuple[float, int]]:
    """The batteries present, in order, and their samples (of integers counted: ``np.unique`` would import
    ``numpy.ma``, a tenth of a JSON Lines replay's start-up)."""
    if instance.dtype.kind in "iu":
        counts = np.bincount(instance, minlength=MAX_INSTANCES + 1)
        present = np.flatnonzero(counts)
        return list(zip(present.tolist(), counts[present].tolist(), strict=True))
    values, counts = np.unique(instance, return_counts=True)
    return list(zip(values.tolist(), counts.tolist(), strict=True))


def _columns(s: BatterySettings, rows: NDArray, now: NDArray, volts: NDArray, amps: NDArray, mah: NDArray) -> _Battery:
    voltage = np.where(np.isfinite(volts) & (volts > 0), volts, 0.0)
    voltage_only = s.monitor == MONITOR_VOLTAGE_ONLY
    current = np.full(len(rows), np.nan) if voltage_only else amps
    measures = np.zeros(len(rows), bool) if voltage_only else ~np.isnan(amps) | ~np.isnan(mah)
    consumed = _consumed(now, current, mah)
    used = voltage
    if s.volt_source == VOLTSRC_RESTING:
        used = _resting(now, voltage, current, measures)
    remaining = s.capacity_mah - consumed
    known = used > 0
    return _Battery(
        s,
        rows,
        now,
        voltage,
        used,
        consumed,
        known & (s.crt_volt > 0) & (used < s.crt_volt),
        known & (s.low_volt > 0) & (used < s.low_volt),
        measures & (s.crt_mah > 0) & (remaining < s.crt_mah),
        measures & (s.low_mah > 0) & (remaining < s.low_mah),
    )


def _consumed(now: NDArray, current: NDArray, mah: NDArray) -> NDArray:
    """BatteryMonitor.read's consumed charge at each sample."""
    known = ~np.isnan(mah)
    if known.all():  # the log's own charge throughout: nothing is integrated
        return np.where(known, mah, 0.0)
    dt = np.diff(now, prepend=now[:1])
    step = ~known & ~np.isnan(current) & (dt > 0) & (dt < MAX_INTEGRATION_MS)
    step[:1] = False  # the first reading has no interval
    add = np.where(step, current * dt.astype(np.float64) * MAH_PER_AMP_MS, -0.0)
    out = np.where(known, mah, 0.0)
    # each run of samples without the log's own charge goes on from the value before it
    edges = np.flatnonzero(np.diff(np.concatenate(([False], ~known, [False])).astype(np.int8)))
    for start, stop in zip(edges[::2].tolist(), edges[1::2].tolist(), strict=True):
        base = out[start - 1] if start > 0 else 0.0
        out[start:stop] = np.cumsum(np.concatenate(([base], add[start:stop])))[1:]
    return out


def _resting(now: NDArray, voltage: NDArray, current: NDArray, measures: NDArray) -> NDArray:
    """voltage_resting_estimate() at each sample: the estimator per sample where it can change (it returns at
    once without a current of at least FLT_EPSILON)."""
    estimator = ResistanceEstimator()
    rows = np.flatnonzero(measures & ~np.isnan(current) & ~(current < FLT_EPSILON))
    state = np.zeros(len(now))
    values = []
    for ms, v, i in zip(now[rows].tolist(), voltage[rows].tolist(), current[rows].tolist(), strict=True):
        estimator.update(ms, v, i)
        values.append(estimator.resting_voltage)
    marks = np.full(len(now), -1, np.int64)
    marks[rows] = np.arange(len(rows))
    last = np.maximum.accumulate(marks)
    if len(rows):
        state = np.where(last >= 0, np.asarray(values, np.float64)[np.maximum(last, 0)], 0.0)
    return np.where(state > voltage, state, voltage)


def _timer(condition: NDArray, now: NDArray, timeout_ms: int) -> NDArray:
    """Where a condition held for more than the timeout: runs over the checked samples, started at a run's first."""
    n = len(condition)
    out = np.zeros(n, bool)
    at = np.flatnonzero(condition)  # worked out where the condition holds only: most samples are healthy
    if timeout_ms <= 0 or not len(at):
        return out
    first = np.empty(len(at), bool)
    first[0], first[1:] = True, np.diff(at) != 1
    start = at[np.maximum.accumulate(np.where(first, np.arange(len(at)), 0))]
    out[at] = ~first & (now[at] - now[start] > timeout_ms)
    return out


def _next_event(b: _Battery, checked: NDArray, level: Level, timer: bool) -> tuple[int, Trigger] | None:
    """The first checked sample (index among the battery's) whose trigger is above ``level``."""
    rows = np.flatnonzero(checked)
    if not len(rows):
        return None
    s = b.settings
    now = b.now[rows]
    timeout = round(s.low_timer_s * 1000)
    cv, lv, cc, lc = b.cv[rows], b.lv[rows], b.cc[rows], b.lc[rows]
    cvf = cv if not timer else _timer(cv, now, timeout)
    lvf = _timer(lv, now, timeout)
    critical = cvf | cc
    candidates = critical if level is Level.LOW else critical | lvf | lc
    hits = np.flatnonzero(candidates)
    if not len(hits):
        return None
    j = int(hits[0])
    k = int(rows[j])
    remaining = s.capacity_mah - float(b.consumed[k])
    used = float(b.used[k])
    if cvf[j]:
        return k, Trigger(Level.CRITICAL, "voltage", used, s.crt_volt)
    if cc[j]:
        return k, Trigger(Level.CRITICAL, "capacity", remaining, s.crt_mah)
    if lvf[j]:
        return k, Trigger(Level.LOW, "voltage", used, s.low_volt)
    return k, Trigger(Level.LOW, "capacity", remaining, s.low_mah)


def _per_sample(failsafe: BatteryFailsafe, table: SampleTable, name: str | None) -> list[tuple[Event, Sample]]:
    """The evaluator, sample by sample (the oracle)."""
    out: list[tuple[Event, Sample]] = []
    for sample in table.samples():
        try:
            events = failsafe.update(sample.t, sample.battery, armed=sample.armed, instance=sample.instance)
        except ValueError as exc:
            raise BattgenError(f"{name}: {sample.place}: {exc}" if name else f"{sample.place}: {exc}") from None
        out.extend((event, sample) for event in events)
    return out

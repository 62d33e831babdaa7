"""ArduPilot DataFlash logs (.bin) for the export: the battery monitor readings (``BAT``, older
``BAT2``/``CURR``/``CURR2``) of :mod:`codegen.inputs.dataflash.log`, one batch per instance.

DataFlash has no message schema in the IR (its layout is in each log's own FMT records), so there is
no mapping file to apply: the four values the reader gives -- ``Volt`` V, ``Curr`` A, ``CurrTot``
mAh, ``RemPct`` % -- become concepts here, with the factors taken from the IR's unit registry.
A value the log lacks is unknown; units come from the log (FMTU) or ArduPilot's logging code
(:mod:`codegen.inputs.dataflash.units`). ``t`` is seconds since the log's first record, whose
``TimeUS`` (µs since boot) is ``Batch.origin_us``; ``armed`` follows
:mod:`codegen.inputs.dataflash.arming` (``ARM`` / ``EV`` records from the state ``LOG_DISARMED``
implies at the first record); ``time`` (UTC) from the first ``GPS`` record with a week
(``GWk``/``GMS`` against its ``TimeUS``, as pymavlink's DataFlash reader sets its clock), where
the log has one.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...inputs.dataflash.arming import armed_at_start
from ...inputs.dataflash.log import (
    FAILSAFE_SUBSYSTEMS,
    ArmingRecord,
    BatteryRecord,
    GpsClock,
    LogStart,
    event_name,
    mode_name,
    open_log,
    reason_name,
    timed_flight_records,
)
from ...ir.units import unit
from .catalog import Catalog
from .columns import ConceptColumn, NDArray, empty_columns
from .context import ARMING_RULES, LogContext, LogText, arming_changes
from .sources import Batch, as_of

MESSAGE = "dataflash.BAT"
# reader attribute -> (DataFlash field, unit, concept)
FIELDS = (
    ("voltage_v", "Volt", "V", "pack_voltage"),
    ("current_a", "Curr", "A", "current"),
    ("consumed_mah", "CurrTot", "mAh", "discharged"),
    ("remaining_pct", "RemPct", "%", "state_of_charge"),
)


INSTANCE_MAX = 255  # AP_BattMonitor logs its instance as a uint8 ('B' in its FMT)


def dataflash_batches(path: Path, name: str, catalog: Catalog) -> list[Batch]:
    """Every battery instance of a DataFlash log as a batch with its concepts filled."""
    log = open_log(path, name)
    readings: dict[int, list[BatteryRecord]] = {}
    arming: list[ArmingRecord] = []
    clock: GpsClock | None = None
    left_out: list[int] = []
    start = LogStart(None, None, None)
    for item in timed_flight_records(log):
        if isinstance(item, LogStart):
            start = item
        elif isinstance(item, ArmingRecord):
            arming.append(item)
        elif isinstance(item, GpsClock):
            clock = clock or item
        elif 0 <= item.instance <= INSTANCE_MAX:
            readings.setdefault(item.instance, []).append(item)
        else:  # a crafted or damaged record: cast, it would join another battery's readings
            left_out.append(item.instance)
    origin_us = start.time_us or 0
    parameters = {} if start.log_disarmed is None else {"LOG_DISARMED": start.log_disarmed}
    initially = armed_at_start(parameters, arming[0].armed if arming else None)
    arm_t = np.array([-np.inf] + [a.time_s - origin_us / 1e6 for a in arming], np.float64)
    arm_v = np.array([initially] + [a.armed for a in arming], bool)
    context = LogContext(
        "dataflash",
        origin_us,
        None if clock is None else clock.utc_us - clock.time_us,
        firmware=start.firmware,
        hardware=start.hardware,
        autopilot="ardupilot",  # DataFlash is ArduPilot's log format
        parameters=dict(start.parameters),
        arming=arming_changes(arm_t, arm_v),
        arming_rule=ARMING_RULES["dataflash"],
        texts=tuple(LogText(_t(at, origin_us), "", text) for at, text in start.texts),
        modes=tuple(_mode(at, number, reason, start.firmware, origin_us) for at, number, reason in start.modes),
        failsafes=_failsafes(start, origin_us),
        events=tuple((_t(at, origin_us), event_name(event)) for at, event in start.events),
    )
    out: list[Batch] = []
    for instance, rows in sorted(readings.items()):
        n = len(rows)
        columns: dict[str, NDArray] = {}
        for attr, field, _, _ in FIELDS:
            columns[field] = np.array([np.nan if getattr(r, attr) is None else getattr(r, attr) for r in rows])
        t = np.array([r.time_s for r in rows], np.float64) - origin_us / 1e6
        batch = Batch(MESSAGE, n, columns, t, np.full(n, instance), origin_us=origin_us)
        if start.firmware:
            batch.notes.append(f"firmware: {start.firmware!r}")
        batch.concepts = _concepts(catalog, columns, n)
        if clock is not None:  # the log's clock against UTC, from its first GPS record with a week
            batch.utc_offset_us = clock.utc_us - clock.time_us
            batch.time_us = np.round(t * 1e6).astype(np.int64) + origin_us + batch.utc_offset_us
        batch.armed = as_of(arm_t, arm_v, t)
        batch.context = context
        if left_out and not out:
            batch.warnings.append(
                f"{name}: {len(left_out)} battery record(s) left out whose instance is no battery's "
                f"(0..{INSTANCE_MAX}): {', '.join(map(str, left_out[:5]))}{' ...' if len(left_out) > 5 else ''}"
            )
        if log.skipped_notes:
            batch.notes.append(f"{len(log.skipped_notes)} notes from the DataFlash reader (skipped data)")
        out.append(batch)
    return out


def _t(seconds: float | None, origin_us: int) -> float:
    """A record's time in ``t`` (a record without any time: the log's start)."""
    return 0.0 if seconds is None else max(seconds - origin_us / 1e6, 0.0)


def _mode(
    seconds: float | None, number: int, reason: int | None, firmware: str | None, origin_us: int
) -> tuple[float, str]:
    why = "" if reason is None else f" ({reason_name(reason)})"
    return _t(seconds, origin_us), mode_name(number, firmware) + why


def _failsafes(start: LogStart, origin_us: int) -> tuple[tuple[float, str], ...]:
    """The failsafes ArduPilot logged: a MODE change for a failsafe reason, an ERR of a failsafe subsystem (its
    code 0, resolved, left out)."""
    out = [
        _mode(at, number, reason, start.firmware, origin_us)
        for at, number, reason in start.modes
        if reason is not None and "FAILSAFE" in reason_name(reason)
    ]
    out += [
        (_t(at, origin_us), f"{FAILSAFE_SUBSYSTEMS[subsystem]} (ECode {code})")
        for at, subsystem, code in start.errors
        if subsystem in FAILSAFE_SUBSYSTEMS and code != 0
    ]
    return tuple(sorted(out))


def _concepts(catalog: Catalog, columns: dict[str, NDArray], n: int) -> dict[str, ConceptColumn]:
    out = empty_columns(catalog.concepts, n)
    for _, field, symbol, concept in FIELDS:
        target = out[concept]
        assert target.concept.unit is not None
        mul, add = unit(symbol).factor_to(target.concept.unit)
        values = columns[field]
        target.set(values * mul + add, ~np.isnan(values))
    return out

"""What a PX4 ULog recorded of its battery failsafe, for a replay and for checking the replay against it.

The batteries come through the battery view (:mod:`codegen.apps.battery.view`, the one reading ``export`` and
``report`` share: its clock, its "armed", its context with the log's parameters and firmware): per battery its
updates' time, state of charge (``battery_status.remaining``, the estimate the firmware's warning was computed
from), ``connected``, ``time_remaining_s`` and the warning the firmware logged.

What commander did comes from topics the battery view does not read, through the same ULog reader
(:class:`codegen.inputs.ulog.columns.UlogColumns`): ``failsafe_flags.battery_warning`` and
``.battery_low_remaining_time`` (v1.14+; older logs do not record them), ``vehicle_status.nav_state`` (the mode a
failsafe action puts the vehicle in) and ``rtl_time_estimate`` (``safe_time_estimate`` where ``valid``: what the
remaining-flight-time failsafe compares the batteries' ``time_remaining_s`` with).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...inputs.model import UorbClass
from ...inputs.ulog.columns import UlogColumns
from ..battery.catalog import bundled_catalog
from ..battery.columns import NDArray
from ..battery.context import LogContext
from ..battery.sources import model_of
from ..battery.view import read_view


@dataclass
class Px4Battery:
    """One battery's updates as logged, in time order (``battery``: 1-based, as PX4 numbers its batteries)."""

    battery: int
    t: NDArray  # s since the log's start
    boot_s: NDArray  # s since boot (the battery library's clock)
    remaining: NDArray  # the state of charge, 0..1 (NaN: unknown)
    connected: NDArray  # bool
    warning: NDArray  # the logged battery_status.warning (-1: unknown)
    time_remaining: NDArray  # s (NaN: unknown)
    armed: NDArray  # bool, the view's arming state as of each update


@dataclass
class Topic:
    """A topic's timestamps (s since the log's start) and one field's values (int64; float64 with ``real``)."""

    t: NDArray
    values: NDArray


@dataclass
class Px4Log:
    context: LogContext
    batteries: list[Px4Battery] = field(default_factory=list)
    failsafe_warning: Topic | None = None  # failsafe_flags.battery_warning
    nav_state: Topic | None = None  # vehicle_status.nav_state
    low_remaining_time: Topic | None = None  # failsafe_flags.battery_low_remaining_time
    rtl_safe_time: Topic | None = None  # rtl_time_estimate.safe_time_estimate, NaN where not valid


class NoBatteryRecords(ValueError):
    """A readable log without battery records (commands exit 1 for it, or 0 with ``--allow-empty``)."""


def read_px4_log(path: Path, name: str | None = None) -> Px4Log:
    """A PX4 log's battery updates and commander topics (an InputError, or another BattgenError, if unreadable; a
    ValueError for a log of another firmware)."""
    display = name or path.as_posix()
    parts: dict[int, list[tuple[NDArray, ...]]] = {}
    context: LogContext | None = None
    for chunk in read_view(path, display):
        context = context or chunk.batch.context
        if not chunk.n or chunk.batch.message != "uorb.BatteryStatus":
            continue
        batch = chunk.batch
        warning = chunk.concepts["warning"]
        logged = np.where(warning.valid, warning.values, -1).astype(np.int8)
        armed = np.zeros(chunk.n) if batch.armed is None else np.nan_to_num(np.asarray(batch.armed, np.float64))
        connected = chunk.concepts["connected"]
        for b in np.unique(chunk.battery).tolist():
            rows = chunk.battery == b
            parts.setdefault(int(b) + 1, []).append(
                (
                    np.asarray(batch.t, np.float64)[rows],
                    chunk.number("state_of_charge")[rows],
                    (connected.valid & connected.values.astype(bool))[rows],
                    logged[rows],
                    chunk.number("time_remaining")[rows],
                    (armed == 1.0)[rows],
                )
            )
    if context is None:
        raise NoBatteryRecords(f"{display}: expected battery_status records, found none")
    if context.autopilot != "px4":
        raise ValueError(f"{display}: expected a PX4 log (a ULog), found a {context.kind} log of {context.autopilot}")
    out = Px4Log(context)
    origin_s = (context.start_us or 0) / 1e6
    for battery in sorted(parts):
        t, soc, conn, warn, left, armed = (np.concatenate(c) for c in zip(*parts[battery], strict=True))
        order = np.argsort(t, kind="stable")
        t = t[order]
        out.batteries.append(
            Px4Battery(battery, t, t + origin_s, soc[order], conn[order], warn[order], left[order], armed[order])
        )
    _read_commander_topics(path, display, context, out)
    return out


def _read_commander_topics(path: Path, name: str, context: LogContext, out: Px4Log) -> None:
    model = model_of(bundled_catalog(), "uorb.BatteryStatus")
    if not isinstance(model, UorbClass):
        return
    start = context.start_us or 0
    with UlogColumns(path, name, model) as log:
        present = {topic for topic, multi_id in log.log.topics() if multi_id == 0}

        def topic(topic: str, field_name: str, real: bool = False) -> Topic | None:
            if topic not in present or field_name not in log.log.layout(topic).names:
                return None
            records = log.records(topic, 0)
            if not len(records):
                return None
            t = (records["timestamp"].astype(np.int64) - start) / 1e6
            order = np.argsort(t, kind="stable")
            values = np.asarray(records[field_name]).astype(np.float64 if real else np.int64)[order]
            return Topic(t[order], values)

        out.failsafe_warning = topic("failsafe_flags", "battery_warning")
        out.low_remaining_time = topic("failsafe_flags", "battery_low_remaining_time")
        out.nav_state = topic("vehicle_status", "nav_state")
        safe, valid = topic("rtl_time_estimate", "safe_time_estimate", True), topic("rtl_time_estimate", "valid")
        if safe is not None and valid is not None:
            out.rtl_safe_time = Topic(safe.t, np.where(valid.values != 0, safe.values, np.nan))

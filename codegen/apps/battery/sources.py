"""Reading one log of any kind into batches of source columns for the export.

A :class:`Batch` is the records of one source message in one log (one ULog topic instance, the
BATTERY_STATUS frames of a tlog, the records of a JSON Lines file): the message's fields as
columns, plus the context the table needs (time since the log's start, time of day, vehicle,
instance, armed state). Kinds: PX4 ULog (.ulg) read as columns, MAVLink telemetry logs (.tlog)
and JSON Lines (.jsonl/.ndjson) read record by record through the shared readers
(:mod:`codegen.inputs`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, cast

import numpy as np

from ...backends.python import naming
from ...errors import BattgenError
from ...inputs.dataflash.log import shortest_float32
from ...inputs.files.held import Buffer
from ...inputs.files.kinds import LOG_KINDS, detect
from ...inputs.model import MessageClass, UorbClass
from ...inputs.records import InputError, Record, Unreadable
from ...inputs.ulog.columns import UlogColumns
from ...ir import ArrayType, Field, Message, PrimitiveKind, PrimitiveType, Schema, StringType
from ..schemas.package import bundled_package, model_class
from .catalog import RECORD_ENDPOINTS, Catalog
from .columns import ConceptColumn, NDArray, length_key
from .context import (
    ARMING_RULES,
    SYSLOG_LEVELS,
    LogContext,
    LogText,
    arming_changes,
    px4_battery_failsafes,
    px4_firmware,
    px4_modes,
)


@dataclass
class Batch:
    """The records of one source message in one log, as columns, and their context."""

    message: str  # qualified name
    n: int
    columns: dict[str, NDArray]  # by schema field name; arrays as (n, capacity) matrices
    t: NDArray  # seconds since the log's start (NaN: unknown)
    instance: NDArray  # the log's instance of each record (ULog multi_id, else 0)
    time_us: NDArray | None = None  # microseconds since the Unix epoch
    time_known: NDArray | None = None  # where time_us holds a time (None: everywhere)
    vehicle: NDArray | str | None = None  # one for the batch, or an object array of str / None
    armed: NDArray | None = None  # float 1.0 / 0.0 / NaN (unknown)
    concepts: dict[str, ConceptColumn] | None = None  # filled by the reader (a format without IR mapping)
    origin_us: int = 0  # the log's clock at t = 0 (ULog/DataFlash: µs since boot; tlog: µs since the epoch)
    utc_offset_us: int | None = None  # the log's clock + this = µs since the epoch (None: unknown)
    vehicle_type: int | None = None  # MAVLink MAV_TYPE of the vehicle, where the log says (a tlog's HEARTBEAT)
    notes: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)  # records left out, and why: for the user, not only the record
    context: LogContext | None = None  # what the log says about itself, one object for all its batches


def log_kind(path: Path) -> str:
    """The kind of a log or capture (:func:`codegen.inputs.files.kinds.detect`: content, then name); an InputError for
    a file of another kind."""
    kind = detect(path)
    if kind not in LOG_KINDS:
        expected = (
            "a PX4 ULog (.ulg), MAVLink tlog (.tlog), ArduPilot DataFlash (.bin), CAN capture (.log, .asc, .blf, "
            ".trc) or JSON Lines file"
        )
        raise InputError(path.as_posix(), 0, f"expected {expected}")
    return kind


def model_of(catalog: Catalog, qualified: str) -> MessageClass:
    return model_class(bundled_package(), catalog.schema.message(qualified))


# -- ULog ------------------------------------------------------------------------------------------


def ulog_batches(path: Path, name: str, catalog: Catalog, source: Buffer | None, all_fields: bool) -> Iterator[Batch]:
    model = model_of(catalog, "uorb.BatteryStatus")
    fields = None if all_fields else catalog.source(model.QUALIFIED_NAME).fields
    if not isinstance(model, UorbClass):
        raise BattgenError("the generated uorb.BatteryStatus has no ULog support: run 'battgen generate'")
    with UlogColumns(path, name, model, source) as log:
        start = log.start_us
        if not 0 <= start < 1 << 63:  # the header's uint64: beyond int64 no time column can hold it
            raise InputError(name, 0, f"a start time of {start} µs in the header: expected at most 2^63 - 1")
        offset = log.utc_offset_us()
        armed = log.armed()
        context = ulog_context(log, armed, offset)
        for inst in log.instances(fields=fields):
            stamps = inst.timestamps
            t = (stamps.astype(np.int64) - start) / 1e6 if stamps is not None else np.full(inst.n, np.nan)
            batch = Batch(model.QUALIFIED_NAME, inst.n, inst.columns, t, np.full(inst.n, inst.multi_id))
            batch.origin_us, batch.utc_offset_us = start, offset
            if stamps is not None and offset is not None:
                batch.time_us = stamps.astype(np.int64) + offset
            if log.vehicle is not None:
                batch.vehicle = log.vehicle
            if stamps is not None and armed is not None:
                batch.armed = as_of(armed[0], armed[1], stamps)
            batch.context = context
            yield batch


def ulog_context(log: UlogColumns, armed: tuple[NDArray, NDArray] | None, utc_offset_us: int | None) -> LogContext:
    """A ULog's context (:mod:`.context`): its info messages, initial parameters and arming state."""
    info = log.info
    # a float parameter as a person reads it (0.005, not 0.004999999888241291); an int32 one as it is
    parameters = {k: shortest_float32(v) if isinstance(v, float) else float(v) for k, v in log.parameters.items()}
    mav_type = parameters.get("MAV_TYPE")
    hardware = info.get("ver_hw")
    changes: tuple[tuple[float, bool], ...] = ()
    if armed is not None:
        changes = arming_changes((armed[0].astype(np.int64) - log.start_us) / 1e6, armed[1])
    modes, failsafes = px4_modes(log.nav_states(), log.start_us)
    failsafes = tuple(sorted(failsafes + px4_battery_failsafes(log.battery_failsafe_flags(), log.start_us)))
    texts = tuple(
        LogText((stamp - log.start_us) / 1e6, _syslog(level), text.rstrip("\t\n\x00"))
        for level, stamp, text in log.logged()
    )
    return LogContext(
        "ulog",
        log.start_us,
        utc_offset_us,
        log.vehicle,
        int(mav_type) if mav_type is not None else None,
        "px4",
        px4_firmware(info),
        str(hardware) if hardware else None,
        parameters,
        changes,
        ARMING_RULES["ulog"] if armed is not None else "",
        texts,
        modes,
        failsafes,
    )


def _syslog(level: int) -> str:
    """A ULog text's level byte (an ASCII digit, '0' emergency to '7' debug, as syslog) by name."""
    index = level - ord("0")
    return SYSLOG_LEVELS[index] if 0 <= index < len(SYSLOG_LEVELS) else ""


def as_of(times: NDArray, values: NDArray, at: NDArray) -> NDArray:
    """The latest of ``values`` at or before each of ``at`` (NaN before the first)."""
    order = np.argsort(times, kind="stable")
    times, values = times[order], values[order].astype(np.float64)
    idx = np.searchsorted(times, at, side="right") - 1
    return np.where(idx >= 0, values[np.maximum(idx, 0)], np.nan)


# -- records read one at a time --------------------------------------------------------------------


def _dtype(ftype: object) -> Any:
    while isinstance(ftype, ArrayType):
        ftype = ftype.element
    if isinstance(ftype, PrimitiveType):
        if ftype.kind is PrimitiveKind.FLOAT:
            return np.float64
        if ftype.kind is PrimitiveKind.BOOL:
            return np.bool_
        if ftype.kind is PrimitiveKind.UINT and ftype.bits > 63:
            return np.uint64
        if ftype.kind in (PrimitiveKind.INT, PrimitiveKind.UINT):
            return np.int64
    return object


def instances_to_columns(
    message: Message, instances: Sequence[object], schema: Schema | None = None, paths: Iterable[str] = ()
) -> dict[str, NDArray]:
    """Decoded records (generated instances) as columns by schema field name; and, given the ``schema``, a column for
    each dotted path of ``paths`` (a number inside a Cyphal composite: ``value.power.voltage.volt``,
    ``temperature_min_max.1.kelvin``), keyed by the path as the mapping's rules name it."""
    out: dict[str, NDArray] = {}
    for f in message.fields:
        if not f.is_padding:
            attr = naming.field_identifier(f.name, f.pattern)
            out.update(_field_columns(f, f.name, [getattr(x, attr) for x in instances]))
    for path in paths:
        if "." not in path or schema is None:
            continue
        steps = path.split(".")
        getters: list[str | int] = []
        for i, step in enumerate(steps):
            if step.isdigit():
                getters.append(int(step))
            else:
                at = schema.field_at(message.qualified_name, ".".join(steps[: i + 1]))
                getters.append(naming.field_identifier(at.name, at.pattern))
        values = [_follow(x, getters) for x in instances]
        out.update(_field_columns(schema.field_at(message.qualified_name, path), path, values))
    return out


def _follow(instance: object, getters: Sequence[str | int]) -> object:
    value = instance
    for g in getters:
        value = value[g] if isinstance(g, int) else getattr(value, g)  # type: ignore[index]
    return value


def _field_columns(f: Field, key: str, values: Sequence[Any]) -> dict[str, NDArray]:
    """One field's values as its column (an array field: a matrix, and its lengths if it is dynamic)."""
    dtype = _dtype(f.type)
    texts = any(isinstance(v, bytes | str) for v in values)
    if isinstance(f.type, ArrayType) and not isinstance(f.type.element, StringType) and not texts:
        width = f.type.capacity or max((len(v) for v in values), default=0)
        matrix = np.zeros((len(values), width), dtype)
        for i, v in enumerate(values):
            matrix[i, : len(v)] = v
        out = {key: matrix}
        if f.type.dynamic:
            out[length_key(key)] = np.array([len(v) for v in values], np.int64)
        return out
    column = np.empty(len(values), object if texts else dtype)
    column[:] = values
    return {key: column}


FloatFields = tuple[tuple[str, Any], ...]  # (schema name, numpy type) of each float16/float32 field of a message


def float_fields(message: Message) -> FloatFields:
    """A message's float16 and float32 fields (and arrays of them), with the numpy type that stores each: found once
    per message, not per record (:func:`stored_data` runs for every record)."""
    out = []
    for f in message.fields:
        ftype = f.type.element if isinstance(f.type, ArrayType) else f.type
        if isinstance(ftype, PrimitiveType) and ftype.kind is PrimitiveKind.FLOAT and ftype.bits in (16, 32):
            out.append((f.name, np.float16 if ftype.bits == 16 else np.float32))
    return tuple(out)


def stored_data(fields: FloatFields, data: Mapping[str, Any]) -> dict[str, Any]:
    """A record's plain data with each float16/float32 value (``fields``: :func:`float_fields`) as its field stores
    it: a float32 ``voltage_v`` of 5e-324 is 0.0, uORB's unknown, as the firmware compares it (a value beyond the
    type stays, to be reported)."""
    out = dict(data)
    with np.errstate(over="ignore"):
        for name, narrow in fields:
            value = out.get(name)
            if isinstance(value, list):
                out[name] = [_narrowed(v, narrow) for v in value]
            elif value is not None:
                out[name] = _narrowed(value, narrow)
    return out


def _narrowed(value: Any, narrow: Any) -> Any:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return value  # not a number: from_dict says what it expected
    stored = float(narrow(value))
    return stored if math.isfinite(stored) or not math.isfinite(value) else value  # beyond the type: left to say so


JSONL_CHUNK = 1 << 16  # records per batch of a JSON Lines file: memory stays flat whatever its length
_LISTED = 10  # records left out that a batch's notes name one by one (the rest are counted)


def jsonl_batches(path: Path, name: str, catalog: Catalog, message: str | None) -> Iterator[Batch]:
    """A JSON Lines file's records in batches of :data:`JSONL_CHUNK`. A record whose number does not fit its
    field's type (a uORB ``id`` of 2^32 + 1, a float32 of 1e300) is left out with a note naming it: cast, it would
    wrap into another battery's number (or be infinity)."""
    from ...inputs.documents import read_jsonl  # with YAML's reader: imported by the runs that read JSON Lines

    qualified: str | None = message
    records: list[Record] = []
    first_stamp: float | None = None
    for item in read_jsonl(path, name):
        if isinstance(item, Unreadable):
            raise InputError(name, item.line, item.message)
        if isinstance(item, Record):
            qualified = qualified or guess_message(catalog, item, name)
            records.append(item)
            if len(records) == JSONL_CHUNK:
                batch, first_stamp = _jsonl_batch(catalog, qualified, records, name, first_stamp)
                yield batch
                records = []
    if records and qualified is not None:
        yield _jsonl_batch(catalog, qualified, records, name, first_stamp)[0]


def _jsonl_batch(
    catalog: Catalog, qualified: str, records: list[Record], name: str, first: float | None
) -> tuple[Batch, float | None]:
    """One batch of JSON Lines records and the timestamp its ``t`` counts from: the first batch's smallest
    (``first``, once an earlier batch had one)."""
    model = model_of(catalog, qualified)
    message = catalog.schema.message(qualified)
    limits, floats = number_limits(message), float_fields(message)
    instances = []
    notes: list[str] = []
    left_out = 0
    for rec in records:
        try:
            data = stored_data(floats, rec.data) if isinstance(rec.data, dict) else rec.data
            instance = model.from_dict(data)
        except (ValueError, TypeError, KeyError) as exc:
            raise InputError(name, rec.line, f"expected a {qualified} record: {exc}") from None
        unfit = _unfit(instance, limits)
        if unfit is not None:
            left_out += 1
            if left_out <= _LISTED:
                notes.append(f"{name}:{rec.line}: {unfit}: record left out")
            continue
        instances.append(instance)
    if left_out > _LISTED:
        notes.append(f"{name}: {left_out - _LISTED} more records left out whose numbers do not fit their types")
    columns = instances_to_columns(message, instances)
    n = len(instances)
    t = np.full(n, np.nan)
    stamps = columns.get("timestamp")
    origin = first
    if stamps is not None and stamps.ndim == 1 and stamps.dtype != object and n:
        origin = float(stamps.min()) if first is None else first
        t = (stamps - origin) / 1e6
    return Batch(qualified, n, columns, t, np.zeros(n, np.int64), warnings=notes), origin


Limits = list[tuple[str, str, float, float]]  # (attribute, type name, lowest, highest) of each number field


def number_limits(message: Message) -> Limits:
    """The integer and float16/float32 fields of a message (and arrays of them) with the range of their IR type."""
    out: Limits = []
    for f in message.fields:
        ftype = f.type.element if isinstance(f.type, ArrayType) else f.type
        if f.is_padding or not isinstance(ftype, PrimitiveType) or ftype.kind is PrimitiveKind.BOOL:
            continue
        if ftype.kind in (PrimitiveKind.INT, PrimitiveKind.UINT) or (
            ftype.kind is PrimitiveKind.FLOAT and ftype.bits in (16, 32)
        ):
            lo, hi = cast(tuple[float, float], ftype.value_range)
            out.append((naming.field_identifier(f.name, f.pattern), ftype.name, lo, hi))
    return out


def _unfit(instance: object, limits: Limits) -> str | None:
    """The first number of a record outside its field's type (a finite float beyond float32 too: stored, it
    would be infinity), said as validate says it; None if all fit."""
    for attr, type_name, lo, hi in limits:
        value = getattr(instance, attr)
        for v in value if isinstance(value, list) else (value,):
            if isinstance(v, bool) or not isinstance(v, int | float) or (isinstance(v, float) and not math.isfinite(v)):
                continue
            if not lo <= v <= hi:
                bounds = f"+-{hi:g}" if type_name.startswith("float") else f"{int(lo)}..{int(hi)}"
                return f"{attr} = {v} does not fit {type_name} ({bounds})"
    return None


def guess_message(catalog: Catalog, record: Record, name: str) -> str:
    """The first record message (uorb, uorb_v0, mavlink, dronecan) whose fields hold every key of
    the first record; the order settles a record that fits several (uORB versions share names)."""
    data = record.data
    if not isinstance(data, dict) or not data:
        raise InputError(name, record.line, "expected a JSON object per line")
    keys = set(cast(dict[str, Any], data))
    by_endpoint = {s.endpoint: q for q, s in catalog.sources.items()}
    for endpoint in RECORD_ENDPOINTS:
        qualified = by_endpoint.get(endpoint)
        if qualified is not None and keys <= {f.name for f in catalog.schema.message(qualified).fields}:
            return qualified
    raise InputError(
        name,
        record.line,
        f"cannot tell which battery message the records are ({', '.join(sorted(keys)[:6])}...): give --message",
    )

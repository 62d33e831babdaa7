"""PX4 ULog flight logs (.ulg) as columns: every instance (multi_id) of a uORB message's topics,
each field a numpy array, for whole-log work such as ``battgen export``.

The log is memory-mapped and indexed once (:mod:`.ulog_index`: the record walk at C speed, every
decision the generated reader's); a topic instance's records are handed out in chunks of at most
``chunk`` records, each wanted field copied out of every record into a contiguous column (by the
compiled gather, else through a numpy structured dtype of the log's format). Fields are named
and shaped as the generated class has them (arrays as ``(n, capacity)`` matrices) and filled as
:meth:`Log.iter_records` fills a record: a field the log lacks or types otherwise keeps the
class's default, so a column and a record of the same log agree
(tests/apps/test_export_columnar.py checks it on the real logs).

What the log says about itself comes along: its start time, the vehicle (``sys_uuid``), the
offset to UTC when a GPS fix gave one (``vehicle_gps_position.time_utc_usec``), and when the
vehicle was armed (``actuator_armed``).
"""

from __future__ import annotations

import dataclasses
import functools
import re
import struct
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol, cast

from ...errors import cannot_read
from ..files.held import Buffer
from ..model import FormatDiff, UorbClass, ulog_runtime
from ..records import InputError
from . import layouts as ulog_layouts
from .index import gather, record_offsets

NDArray = Any  # numpy arrays
# records per chunk handed out: memory stays flat whatever the log's length. Measured on a million
# records: 2^17 is 7 % faster than 2^16 for 41 MB more peak memory; 2^18, 2 % more for 60 MB more.
CHUNK = 1 << 17
PX4_ARMING_STATE_ARMED = 2  # vehicle_status.arming_state
# records gathered at a time without the compiled gather: a block (some 100 KiB to 1 MiB) stays in the CPU's cache
_BLOCK = 1 << 12
_GATHER_FIELDS = 256  # fields per compiled gather call (it takes at most 512)
_ELEMENT = re.compile(r"(.+)\[(\d+)\]")


class _Layout(Protocol):
    """A log format's flattened layout (the generated ``_ulog.Layout``, a frozen dataclass)."""

    names: tuple[str, ...]
    np_types: tuple[str, ...]
    offsets: tuple[int, ...]
    data_size: int

    def __hash__(self) -> int: ...


class ColumnLog(Protocol):
    """What this module uses of the generated ``_ulog.Log``."""

    timestamp: int
    info: Mapping[str, object]
    parameters: Mapping[str, object]
    formats: Mapping[str, object]
    warnings: list[str]
    logged: list[tuple[int, int, str]]  # (level, timestamp, text)
    logged_tagged: list[tuple[int, int, int, str]]  # (tag, level, timestamp, text)

    data: Any

    def topics(self) -> list[tuple[str, int]]: ...
    def compare(self, cls: Any, *, topic: str | None = None) -> FormatDiff: ...
    def layout(self, topic: str) -> _Layout: ...
    def decoder(self, cls: Any, topic: str) -> Any: ...
    def close(self) -> None: ...


@dataclass(frozen=True)
class TopicColumns:
    """Records of one topic instance (all, or one chunk of them): ``columns`` by the class's field
    names (schema names)."""

    topic: str
    multi_id: int
    n: int
    timestamps: NDArray | None  # microseconds since boot (the log's clock), or None
    columns: dict[str, NDArray]
    unfilled: frozenset[str]  # fields the log lacks or types otherwise: the class's defaults


class UlogColumns:
    """An opened log; :meth:`instances` hands out the records of each topic instance in chunks.

    ``source`` is the file, or a memory map of it the caller already holds (hashed, say), which
    the log then uses as it is and closes.
    """

    def __init__(self, path: Path, name: str, model: UorbClass, source: Buffer | None = None) -> None:
        import numpy  # noqa: F401  (columns need numpy; fail here, with the file named, if absent)

        self.name = name
        self.model = model
        try:
            if source is None and path.stat().st_size == 0:
                raise InputError(name, 0, "empty file: expected a ULog file")
            self.log = cast(ColumnLog, ulog_runtime(model).read(source or path, index=False, warn=False))
            self.offsets = record_offsets(self.log)
        except OSError as exc:
            raise InputError(name, 0, cannot_read(exc)) from None
        except (ValueError, struct.error, IndexError) as exc:  # ULogError is a ValueError
            raise InputError(name, 0, f"expected a ULog file: {exc}") from None

    def close(self) -> None:
        self.log.close()

    def __enter__(self) -> UlogColumns:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def start_us(self) -> int:
        return int(self.log.timestamp)

    @property
    def vehicle(self) -> str | None:
        uuid = self.log.info.get("sys_uuid")
        return str(uuid) if uuid else None

    @property
    def info(self) -> Mapping[str, object]:
        """The log's information messages (``sys_name``, ``ver_sw``, ``ver_hw``, ...), as logged."""
        return self.log.info

    @property
    def parameters(self) -> dict[str, int | float]:
        """The log's parameters as it started (its ``PARAM`` definitions), typed as the log types them (int32 or
        float); numbers only."""
        return {k: v for k, v in self.log.parameters.items() if isinstance(v, int | float) and not isinstance(v, bool)}

    def instances(self, chunk: int | None = None, fields: frozenset[str] | None = None) -> Iterator[TopicColumns]:
        """Every instance of the class's topics that has records, by topic then multi_id, in
        chunks of at most ``chunk`` records; only ``fields`` (and ``timestamp``) if given."""
        topics = self.model.UORB_TOPICS
        for topic, multi_id in self.log.topics():
            if topic in topics:
                yield from self._instance(topic, multi_id, chunk or CHUNK, fields)

    def columns(self, topic: str, multi_id: int, names: list[str], begin: int, end: int) -> dict[str, NDArray]:
        """Fields ``names`` of records ``begin:end`` of a topic instance, each a contiguous array.

        Each record's fields are copied out while its cache lines are loaded: by the compiled
        gather (:mod:`.ulog_index`) in one pass, else a block of records at a time through numpy
        (reading a field out of a large gathered array reads every cache line of it once per
        field: measured 3x the time for 20 fields of 65,536 records).
        """
        import numpy as np

        lay = self.log.layout(topic)
        dtype = record_dtype(lay)
        n = end - begin
        out = {name: np.empty((n, *dtype[name].shape), dtype[name].base) for name in names}
        offsets = self.offsets.get((topic, multi_id), np.zeros(0, np.int64))[begin:end]
        if gather is not None and lay.data_size and n:
            spec = [(cast(int, dtype.fields[name][1]), dtype[name].itemsize, out[name]) for name in names]
            at_offsets = np.ascontiguousarray(offsets, np.int64)
            for first in range(0, len(spec), _GATHER_FIELDS):
                gather(self.log.data, at_offsets, lay.data_size, spec[first : first + _GATHER_FIELDS])
        else:
            for at in range(0, n, _BLOCK):
                block = self.records(topic, multi_id, begin + at, begin + min(n, at + _BLOCK))
                for name in names:
                    out[name][at : at + len(block)] = block[name]
        return {name: _values(values) for name, values in out.items()}

    def records(self, topic: str, multi_id: int, begin: int = 0, end: int | None = None) -> NDArray:
        """Records ``begin:end`` of a topic instance as a numpy structured array laid out as the
        log's format (:func:`record_dtype`): one fancy-indexing step over the file."""
        import numpy as np

        lay = self.log.layout(topic)
        dtype = record_dtype(lay)
        offsets = self.offsets.get((topic, multi_id), np.zeros(0, np.int64))[begin:end]
        data = self.log.data
        if not lay.data_size or not len(offsets):
            return np.zeros(len(offsets), dtype)
        # A view of the file holding a record at every byte offset, indexed by the records' offsets;
        # gathered as opaque bytes (a memcpy each), then read through the format's fields.
        at_every_byte = np.ndarray(
            buffer=data, dtype=np.dtype((np.void, lay.data_size)), shape=(len(data) - lay.data_size + 1,), strides=(1,)
        )
        return at_every_byte[offsets].view(dtype)

    def _instance(self, topic: str, multi_id: int, chunk: int, wanted: frozenset[str] | None) -> Iterator[TopicColumns]:
        import numpy as np

        try:
            diff = self.log.compare(self.model, topic=topic)
            dtype = record_dtype(self.log.layout(topic))
        except (ValueError, struct.error) as exc:
            raise InputError(self.name, 0, f"{topic} multi_id {multi_id}: cannot decode: {exc}") from None
        skip = frozenset({n for n, _ in diff.missing} | {r.name for r in diff.retyped})
        alias, converted = ulog_layouts.plan(diff)
        total = len(self.offsets.get((topic, multi_id), ()))
        defaults = cast(Any, self.model)()
        fields = [(f.metadata.get("name", f.name), getattr(defaults, f.name)) for f in dataclasses.fields(defaults)]
        if not diff.identical and not _columnar(fields, converted):  # kinds only the generated reader maps
            yield self._decoded(topic, multi_id, skip)
            return
        if wanted is not None:
            fields = [(name, d) for name, d in fields if name in wanted or name == "timestamp"]
        names = set(dtype.names or ())
        # schema name -> the log's field read as it is (same type; renamed ones under the log's name)
        read = {name: alias.get(name, name) for name, _ in fields if name not in skip and name not in converted}
        read = {name: log for name, log in read.items() if log in names}
        conv = {name: converted[name] for name, _ in fields if name in converted and converted[name].log in names}
        gathered = sorted(set(read.values()) | {c.log for c in conv.values()})
        for begin in range(0, total, chunk):
            n = min(chunk, total - begin)
            got = self.columns(topic, multi_id, gathered, begin, begin + n)
            out: dict[str, NDArray] = {name: got[log] for name, log in read.items()}
            for name, default in fields:
                if name in conv:
                    out[name] = ulog_layouts.convert(conv[name], got[conv[name].log], default)
                elif name not in out:  # the class's default, as the per-record reader leaves it
                    out[name] = np.tile(default, (n, 1)) if isinstance(default, list) else np.full(n, default)
            stamps = out.get("timestamp") if "timestamp" not in skip else None
            yield TopicColumns(topic, multi_id, n, stamps, out, skip)

    def _decoded(self, topic: str, multi_id: int, skip: frozenset[str]) -> TopicColumns:
        """The columns of a topic instance whose format differs from the class: every record
        decoded by the generated reader (fields matched by name, renames and compatible types
        converted), gathered into columns -- the same values a per-record reader sees."""
        import numpy as np

        try:
            decode = self.log.decoder(self.model, topic)  # what Log.messages() decodes each record with
            records = [decode(o)[0] for o in self.offsets.get((topic, multi_id), ()).tolist()]
        except (ValueError, struct.error) as exc:
            raise InputError(self.name, 0, f"{topic} multi_id {multi_id}: cannot decode: {exc}") from None
        out: dict[str, NDArray] = {}
        for f in dataclasses.fields(cast(Any, self.model)):
            values = [getattr(r, f.name) for r in records]
            if values and isinstance(values[0], list):
                width = max(len(v) for v in values)
                matrix = np.zeros((len(values), width), np.asarray(values[0]).dtype if width else np.float64)
                for i, v in enumerate(values):
                    matrix[i, : len(v)] = v
                out[f.metadata.get("name", f.name)] = matrix
            else:
                out[f.metadata.get("name", f.name)] = np.array(values)
        stamps = out.get("timestamp") if "timestamp" not in skip else None
        return TopicColumns(topic, multi_id, len(records), stamps, out, skip)

    def _topic_records(self, topic: str, fields: tuple[str, ...]) -> NDArray | None:
        """The records of ``topic`` (instance 0) if the log has it with every one of ``fields``."""
        if topic not in self.log.formats:
            return None
        try:
            if not set(fields) <= set(self.log.layout(topic).names):
                return None
            return self.records(topic, 0)
        except (ValueError, struct.error):
            return None

    def utc_offset_us(self) -> int | None:
        """UTC minus the log's clock, from the first GPS record that carries UTC time, if any."""
        import numpy as np

        recs = self._topic_records("vehicle_gps_position", ("time_utc_usec", "timestamp"))
        if recs is None:
            return None
        utc, stamp = recs["time_utc_usec"], recs["timestamp"]
        known = np.nonzero(utc > 0)[0]
        return int(utc[known[0]]) - int(stamp[known[0]]) if len(known) else None

    def nav_states(self) -> tuple[NDArray, NDArray, NDArray | None] | None:
        """(timestamps, nav_state, failsafe) of ``vehicle_status`` (failsafe None where the log lacks it), if the
        log has it: the mode commander put the vehicle in, and whether a failsafe put it there."""
        status = self._topic_records("vehicle_status", ("timestamp", "nav_state"))
        if status is None or not len(status):
            return None
        failsafe = status["failsafe"] if "failsafe" in (status.dtype.names or ()) else None
        return status["timestamp"], status["nav_state"], failsafe

    def battery_failsafe_flags(self) -> tuple[NDArray, NDArray, NDArray | None] | None:
        """(timestamps, battery_warning, battery_low_remaining_time) of ``failsafe_flags`` (PX4 v1.14 and later:
        the inputs commander's failsafe framework acts on; the remaining-time flag None where the log lacks it), if
        the log has it."""
        flags = self._topic_records("failsafe_flags", ("timestamp", "battery_warning"))
        if flags is None or not len(flags):
            return None
        low = flags["battery_low_remaining_time"] if "battery_low_remaining_time" in (flags.dtype.names or ()) else None
        return flags["timestamp"], flags["battery_warning"], low

    def logged(self) -> list[tuple[int, int, str]]:
        """The log's text messages (``L`` and tagged ``C`` records) as (level byte, timestamp, text), by time;
        complete once the log was walked (the columns' reading walks it)."""
        plain = list(self.log.logged)
        tagged = [(level, stamp, text) for _, level, stamp, text in self.log.logged_tagged]
        return sorted(plain + tagged, key=lambda m: m[1])

    def armed(self) -> tuple[NDArray, NDArray] | None:
        """(timestamps, armed) of the vehicle's arming state, if the log has one. The rule: ``vehicle_status``'s
        ``arming_state`` is ARMED (2, in every PX4 version's enum), the state commander decides and publishes; a
        log without it (some older or trimmed logs) falls back to ``actuator_armed.armed``, which PX4 derives from
        it."""
        status = self._topic_records("vehicle_status", ("timestamp", "arming_state"))
        if status is not None and len(status):
            return status["timestamp"], status["arming_state"] == PX4_ARMING_STATE_ARMED
        recs = self._topic_records("actuator_armed", ("timestamp", "armed"))
        if recs is None or not len(recs):
            return None
        return recs["timestamp"], _values(recs["armed"]).astype(bool)


@functools.lru_cache(maxsize=256)
def record_dtype(lay: _Layout) -> Any:
    """A numpy structured dtype for a log format's records: a field per value, ``x[i]`` runs
    joined into one ``(n,)`` array field ``x`` (nested members keep their flattened names)."""
    import numpy as np

    names: list[str] = []
    formats: list[Any] = []
    offsets: list[int] = []
    i, count = 0, len(lay.names)
    while i < count:
        match = _ELEMENT.fullmatch(lay.names[i])
        j = i + 1
        if match and match.group(2) == "0" and "." not in lay.names[i]:
            base, width = match.group(1), np.dtype(lay.np_types[i]).itemsize
            while (
                j < count
                and lay.names[j] == f"{base}[{j - i}]"
                and lay.np_types[j] == lay.np_types[i]
                and lay.offsets[j] == lay.offsets[i] + (j - i) * width
            ):
                j += 1
            names.append(base)
            formats.append((lay.np_types[i], (j - i,)))
        else:
            names.append(lay.names[i])
            formats.append(lay.np_types[i])
        offsets.append(lay.offsets[i])
        i = j
    return np.dtype({"names": names, "formats": formats, "offsets": offsets, "itemsize": lay.data_size})


def _columnar(fields: list[tuple[str, Any]], converted: Mapping[str, ulog_layouts.Conversion]) -> bool:
    """Whether every field of the class is a number or an array of numbers (what the column path
    maps; strings and nested types stay with the generated decoder) and every conversion is of numbers."""
    for _, default in fields:
        values = default if isinstance(default, list) else [default]
        if not all(isinstance(v, int | float) for v in values):
            return False
    return all(ulog_layouts.supported(c) for c in converted.values())


def _values(field: NDArray) -> NDArray:
    """A record field's values; a bool read as the generated decoder reads it (any non-zero byte)."""
    import numpy as np

    if field.dtype.base == np.bool_:
        return field.view(np.uint8) != 0
    return field

"""PX4 ULog flight logs (.ulg) as columns: every instance (multi_id) of a uORB message's topics,
each field a numpy array, for whole-log work such as ``battgen export``.

The log is memory-mapped and indexed once by the generated reader; each topic instance's records
are gathered with one fancy-indexing step (``Log.columns``). Fields are laid out as the generated
class has them (arrays as ``(n, capacity)`` matrices) and filled as :meth:`Log.iter_records`
fills a record: a field the log lacks or types otherwise keeps the class's default, so a column
and a record of the same log agree (tests/inputs/test_ulog_columns.py checks it).

What the log says about itself comes along: its start time, the vehicle (``sys_uuid``), the
offset to UTC when a GPS fix gave one (``vehicle_gps_position.time_utc_usec``), and when the
vehicle was armed (``actuator_armed``).
"""

from __future__ import annotations

import dataclasses
import struct
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol, cast

from .model import FormatDiff, UorbClass, ulog_runtime
from .records import InputError

NDArray = Any  # numpy arrays


class _Layout(Protocol):
    names: list[str]


class ColumnLog(Protocol):
    """What this module uses of the generated ``_ulog.Log``."""

    timestamp: int
    info: Mapping[str, object]
    formats: Mapping[str, object]
    warnings: list[str]

    def topics(self) -> list[tuple[str, int]]: ...
    def compare(self, cls: Any, *, topic: str | None = None) -> FormatDiff: ...
    def layout(self, topic: str) -> _Layout: ...
    def columns(self, topic: str, multi_id: int = 0, *, use_numpy: bool | None = None) -> dict[str, Any]: ...
    def iter_records(self, cls: Any, *, topic: str | None = None, multi_id: int | None = None) -> Iterator[Any]: ...
    def close(self) -> None: ...


@dataclass(frozen=True)
class TopicColumns:
    """The records of one topic instance: ``columns`` by the class's field names (schema names)."""

    topic: str
    multi_id: int
    n: int
    timestamps: NDArray | None  # microseconds since boot (the log's clock), or None
    columns: dict[str, NDArray]
    unfilled: frozenset[str]  # fields the log lacks or types otherwise: the class's defaults


class UlogColumns:
    """An opened log; :meth:`instances` hands out one :class:`TopicColumns` per topic instance."""

    def __init__(self, path: Path, name: str, model: UorbClass) -> None:
        import numpy  # noqa: F401  (columns need numpy; fail here, with the file named, if absent)

        self.name = name
        self.model = model
        try:
            if path.stat().st_size == 0:
                raise InputError(name, 0, "empty file: expected a ULog file")
            self.log = cast(ColumnLog, ulog_runtime(model).read(path, index=True, warn=False))
        except OSError as exc:
            raise InputError(name, 0, f"cannot read file: {exc.strerror or exc}") from None
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

    def instances(self) -> Iterator[TopicColumns]:
        """Every instance of the class's topics that has records, by topic then multi_id."""
        topics = self.model.UORB_TOPICS
        for topic, multi_id in self.log.topics():
            if topic in topics:
                yield self._instance(topic, multi_id)

    def _instance(self, topic: str, multi_id: int) -> TopicColumns:
        import numpy as np

        try:
            diff = self.log.compare(self.model, topic=topic)
            raw = self.log.columns(topic, multi_id, use_numpy=True)
        except (ValueError, struct.error) as exc:
            raise InputError(self.name, 0, f"{topic} multi_id {multi_id}: cannot decode: {exc}") from None
        skip = frozenset({n for n, _ in diff.missing} | {r.name for r in diff.retyped})
        if not diff.identical:  # an older layout: the generated reader maps it record by record
            return self._decoded(topic, multi_id, skip)
        n = len(next(iter(raw.values()))) if raw else 0
        defaults = cast(Any, self.model)()
        out: dict[str, NDArray] = {}
        for f in dataclasses.fields(cast(Any, self.model)):
            name = f.metadata.get("name", f.name)
            default = getattr(defaults, f.name)
            if isinstance(default, list):
                cap = len(default)
                if name not in skip and f"{name}[0]" in raw:
                    out[name] = np.stack([raw[f"{name}[{i}]"] for i in range(cap)], axis=1)
                else:
                    out[name] = np.tile(np.asarray(default), (n, 1))
            elif name not in skip and name in raw:
                out[name] = raw[name]
            else:
                out[name] = np.full(n, default)
        stamps = raw.get("timestamp") if "timestamp" not in skip else None
        return TopicColumns(topic, multi_id, n, stamps, out, skip)

    def _decoded(self, topic: str, multi_id: int, skip: frozenset[str]) -> TopicColumns:
        """The columns of a topic instance whose format differs from the class: every record
        decoded by the generated reader (fields matched by name, renames and compatible types
        converted), gathered into columns -- the same values a per-record reader sees."""
        import numpy as np

        try:
            records = [r.instance for r in self.log.iter_records(self.model, topic=topic, multi_id=multi_id)]
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

    def utc_offset_us(self) -> int | None:
        """UTC minus the log's clock, from the first GPS record that carries UTC time, if any."""
        import numpy as np

        gps = "vehicle_gps_position"
        if gps not in self.log.formats or "time_utc_usec" not in self.log.layout(gps).names:
            return None
        try:
            cols = self.log.columns(gps, 0, use_numpy=True)
        except (ValueError, struct.error):
            return None
        utc, stamp = cols.get("time_utc_usec"), cols.get("timestamp")
        if utc is None or stamp is None:
            return None
        known = np.nonzero(utc > 0)[0]
        return int(utc[known[0]]) - int(stamp[known[0]]) if len(known) else None

    def armed(self) -> tuple[NDArray, NDArray] | None:
        """(timestamps, armed) of the ``actuator_armed`` records, if the log has them."""
        topic = "actuator_armed"
        if topic not in self.log.formats or "armed" not in self.log.layout(topic).names:
            return None
        try:
            cols = self.log.columns(topic, 0, use_numpy=True)
        except (ValueError, struct.error):
            return None
        if "timestamp" not in cols or not len(cols["timestamp"]):
            return None
        return cols["timestamp"], cols["armed"].astype(bool)

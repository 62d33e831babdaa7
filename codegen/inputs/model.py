"""What the readers and applications use of a generated package, as typing Protocols.

battgen's engines run on whatever package ``battgen generate`` wrote (the committed ``generated/``
or one made on the fly for another schema folder), imported by name; these protocols say which of
its attributes they rely on, so that the code using them is type-checked instead of probing with
``hasattr``. Every generated message class has :class:`MessageClass`'s members; the classes with a
binary codec (uORB, MAVLink, DroneCAN) also :class:`DecodingClass`'s, and their instances
:class:`Encodable`'s; uORB classes are :class:`UorbClass` and MAVLink classes :class:`MavlinkClass`
(checked with ``isinstance``, which looks at the class object's attributes).

The runtime modules a generated package carries for logs (``_ulog``, ``_mavlink``) are described
here too, as far as the log readers use them.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
from collections.abc import Callable, Container, Iterable, Iterator, Mapping, Sequence
from typing import TYPE_CHECKING, Any, Protocol, cast, runtime_checkable

if TYPE_CHECKING:
    import mmap


class Violation(Protocol):
    """One broken rule reported by a generated ``validate()`` (``_validate.Violation``)."""

    @property
    def path(self) -> str: ...
    @property
    def rule(self) -> str: ...
    @property
    def value(self) -> object: ...
    @property
    def limit(self) -> object: ...
    @property
    def message(self) -> str: ...
    @property
    def severity(self) -> str: ...


class PlainData(Protocol):
    """An object that gives its plain data (a generated message, the converters' concept state)."""

    def to_dict(self) -> dict[str, Any]: ...


class GeneratedMessage(PlainData, Protocol):
    """An instance of a generated message class."""

    def validate(self) -> Sequence[Violation]: ...


class PlainClass(Protocol):
    """A class that builds its instances from plain data (``DataError`` on data that does not fit)."""

    __name__: str

    def from_dict(self, data: Any, /) -> PlainData: ...


@runtime_checkable
class MessageClass(PlainClass, Protocol):
    """A generated message class (the class object): a dataclass whose fields carry the schema's
    metadata (``dataclasses.fields(cls)[i].metadata["name"]`` is the field's schema name)."""

    QUALIFIED_NAME: str
    __module__: str

    def from_dict(self, data: Any, /) -> GeneratedMessage: ...


@runtime_checkable
class DecodingClass(MessageClass, Protocol):
    """A generated class with a binary codec (uORB, MAVLink, DroneCAN)."""

    def decode(self, data: bytes, /) -> GeneratedMessage: ...


@runtime_checkable
class Encodable(Protocol):
    """An instance of a generated class with a binary codec."""

    def encode(self) -> bytes: ...


@runtime_checkable
class UorbClass(DecodingClass, Protocol):
    """A generated uORB class: its ULog topics and format (read by the generated ``_ulog``)."""

    UORB_TOPICS: tuple[str, ...]

    def ulog_format(self) -> object: ...


@runtime_checkable
class MavlinkClass(DecodingClass, Protocol):
    """A generated MAVLink class: its message id (frames are checked with its CRC_EXTRA)."""

    MSG_ID: int
    CRC_EXTRA: int


def field_names(cls: MessageClass) -> set[str]:
    """The schema names of a generated class's fields."""
    return {f.metadata.get("name", f.name) for f in dataclasses.fields(cast(Any, cls))}


def package_name(cls: MessageClass) -> str:
    """The import name of the generated package a class belongs to: the nearest package above the
    class's module that holds the generated ``_meta`` module (messages may sit in subpackages,
    ``dronecan.uavcan.equipment.power``)."""
    return _package_of_module(cls.__module__)


@functools.cache
def _package_of_module(module: str) -> str:
    parts = module.split(".")
    for end in range(len(parts) - 1, 0, -1):
        name = ".".join(parts[:end])
        try:
            importlib.import_module(name + "._meta")
        except ImportError:
            continue
        return name
    return parts[0]


# ------------------------------------------------------------------------------------------------
# the generated log runtimes


class FormatChange(Protocol):
    """A field the log types otherwise than the schema (``_ulog.Retyped``)."""

    name: str
    schema: str
    log: str


class FormatDiff(Protocol):
    """How a log's format for a topic differs from a generated class (``_ulog.FormatDiff``)."""

    topic: str
    message: str
    missing: tuple[tuple[str, str], ...]
    extra: tuple[tuple[str, str], ...]
    retyped: tuple[FormatChange, ...]
    identical: bool
    renamed: tuple[tuple[str, str], ...]
    converted: tuple[FormatChange, ...]

    @property
    def matches(self) -> bool: ...
    def to_dict(self) -> dict[str, Any]: ...


class LogRecord(Protocol):
    """One record of ``Log.iter_records`` (``_ulog.Record``)."""

    offset: int
    multi_id: int
    topic: str
    instance: GeneratedMessage
    extras: Mapping[str, Any]
    unfit: tuple[str, ...]


class UlogLog(Protocol):
    """An opened ULog file (``_ulog.Log``)."""

    formats: Mapping[str, object]
    warnings: list[str]

    def compare(self, cls: Any, *, topic: str | None = None) -> FormatDiff: ...
    def layout(self, topic: str) -> object: ...
    def iter_records(self, cls: Any, *, topic: str | Iterable[str] | None = None) -> Iterator[LogRecord]: ...
    def topics(self) -> list[tuple[str, int]]: ...
    def columns(self, topic: str, multi_id: int = 0, *, use_numpy: bool | None = None) -> dict[str, Any]: ...
    def decoder(self, cls: Any, topic: str) -> Callable[[int], tuple[Any, Mapping[str, Any], tuple[str, ...]]]: ...
    def close(self) -> None: ...


class UlogStream(Protocol):
    """The records of one topic instance a walk found (``_ulog.Stream``): payload offsets listed
    in ``offsets`` (a walk without an index moves them on, counting them in ``done``)."""

    key: tuple[str, int]  # (topic, multi_id)
    offsets: list[int]
    done: int


class UlogBinding(Protocol):
    """Where a msg_id's data records go (``_ulog.Binding``): a stream, and the accepted record sizes."""

    @property
    def stream(self) -> UlogStream: ...
    @property
    def lo(self) -> int: ...
    @property
    def hi(self) -> int: ...


class UlogWalk(Protocol):
    """The walking API of ``_ulog.Log``: what a faster walker of the data section (the compiled
    index, :mod:`.ulog_index`) uses to walk it with the generated reader's rules."""

    KNOWN_TYPES: frozenset[int]  # record types the reader knows (others of size 0 or > 10000: corruption)
    data: Any  # the file: bytes or a memory map
    walked: bool
    indexed: bool

    @property
    def segments(self) -> list[tuple[int, int]]: ...
    @property
    def streams(self) -> dict[tuple[str, int], UlogStream]: ...
    def bindings(self) -> dict[int, UlogBinding]: ...
    def binding(self, msg_id: int) -> UlogBinding | None: ...
    def index(self) -> dict[tuple[str, int], UlogStream]: ...
    def begin_walk(self) -> UlogWalk: ...
    def end_walk(self, walk: Any, *, indexed: bool) -> None: ...
    def step(self, pos: int, size: int, kind: int, end: int, at_eof: bool) -> int: ...
    def walk(self, pos: int, end: int, at_eof: bool, limit: int) -> int: ...


class UlogFormat(Protocol):
    name: str


class UlogRuntime(Protocol):
    """The generated ``_ulog`` module."""

    def read(self, source: Any, *, index: bool = True, warn: bool = True) -> UlogLog: ...
    def format_of(self, cls: Any) -> UlogFormat: ...


class Frame(Protocol):
    """One MAVLink frame (``_mavlink.Frame``)."""

    msgid: int
    seq: int
    sysid: int
    compid: int
    payload: bytes


class StreamParser(Protocol):
    """The generated MAVLink byte-stream parser and its counters (``_mavlink.StreamParser``)."""

    frames: int
    bad_crc: int
    unknown_msgid: int
    skipped_bytes: int
    last_error: str | None

    def feed(self, data: bytes) -> list[Frame]: ...
    @property
    def pending(self) -> int: ...


class MavlinkRuntime(Protocol):
    """The generated ``_mavlink`` module."""

    REGISTRY: dict[int, tuple[int, str, int, str]]  # msgid -> (CRC_EXTRA, class name, max length, name)

    def parse_frame(self, data: bytes) -> Frame: ...
    def scan_frames(
        self, data: bytes | mmap.mmap, pos: int, end: int, *, gap: int = 0, wanted: Container[int] | None = None
    ) -> tuple[list[Frame], list[int], int, int]: ...
    def StreamParser(self) -> StreamParser: ...  # the class, called to make one


def ulog_runtime(cls: MessageClass) -> UlogRuntime:
    """The ``_ulog`` module of the generated package a uORB class belongs to."""
    return cast(UlogRuntime, importlib.import_module(package_name(cls) + "._ulog"))


def mavlink_runtime(cls: MessageClass) -> MavlinkRuntime:
    """The ``_mavlink`` module of the generated package a MAVLink class belongs to."""
    return cast(MavlinkRuntime, importlib.import_module(package_name(cls) + "._mavlink"))


@runtime_checkable
class DronecanClass(MessageClass, Protocol):
    """A generated DroneCAN class: its data type id (None for a type without a default id) and signature."""

    DATA_TYPE_ID: int | None
    DATA_TYPE_SIGNATURE: int

    def decode(self, data: bytes, /, *, tao: bool = True) -> GeneratedMessage: ...


@runtime_checkable
class CyphalClass(MessageClass, Protocol):
    """A generated Cyphal class: its fixed port id (None for most types) and its codec (a whole transfer's
    payload: no delimiter header; padding past the last field is ignored, as Cyphal's implicit extension has it)."""

    FIXED_PORT_ID: int | None
    EXTENT_BYTES: int

    def decode(self, data: bytes, /) -> GeneratedMessage: ...

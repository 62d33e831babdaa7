# Copied by battgen from codegen/backends/python/runtime/_ulog_writer.py; do not edit here, edit it there.
"""Writing ULog files from generated uORB messages: :class:`Writer` and :func:`write`. Part of the
ULog runtime that ``_ulog`` re-exports.
"""

from __future__ import annotations

import os
import struct
from collections.abc import Iterable, Mapping
from typing import Any, BinaryIO

from ._ulog_format import HEAD, MAGIC, U16, U64, VERSION, Format, ULogError, format_of, layout


def _info_key(type_text: str, key: str) -> bytes:
    text = f"{type_text} {key}".encode()
    if len(text) > 255:
        raise ULogError(f"info/parameter key too long: {key!r}")
    return bytes((len(text),)) + text


def _typed_value(key: str, value: object) -> bytes:
    """key_len, 'type key', value of an 'I' or 'P' record, the type chosen from the Python value."""
    if isinstance(value, str):
        data = value.encode("utf-8")
        return _info_key(f"char[{len(data)}]", key) + data
    if isinstance(value, bool):
        return _info_key("bool", key) + struct.pack("<?", value)
    if isinstance(value, int):
        if -(2**31) <= value < 2**31:
            return _info_key("int32_t", key) + struct.pack("<i", value)
        return _info_key("int64_t", key) + struct.pack("<q", value)
    if isinstance(value, float):
        return _info_key("float", key) + struct.pack("<f", value)
    raise ULogError(f"{key}: expected a str, bool, int or float value, got {value!r}")


class Writer:
    """Writes a ULog file: header, flag bits, info, parameters and formats first, then data.

    Every class (and topic) to log must be known before the first record: pass them as
    ``messages`` or call :meth:`define`; a :meth:`write` before any record defines its class
    itself. Subscriptions ('A') are written when a (topic, multi_id) first gets data.
    """

    def __init__(
        self,
        target: str | os.PathLike[str] | BinaryIO,
        *,
        timestamp: int = 0,
        info: Mapping[str, str | int | float | bool] | None = None,
        parameters: Mapping[str, int | float] | None = None,
        messages: Iterable[type[Any]] = (),
    ) -> None:
        if isinstance(target, str | os.PathLike):
            self._out: BinaryIO = open(target, "wb")  # closed by close()
            self._owned = True
        else:
            self._out, self._owned = target, False
        self._timestamp = timestamp
        self._info = dict(info or {})
        self._parameters = dict(parameters or {})
        self._formats: dict[str, Format] = {}  # every format to write, nested ones first
        self._topics: dict[tuple[type[Any], str], int] = {}  # (class, topic) -> data bytes
        self._ids: dict[tuple[type[Any], str, int], tuple[bytes, int]] = {}  # -> ('D' record prefix, data bytes)
        self._buf = bytearray()
        self._started = False
        self._closed = False
        for cls in messages:
            self.define(cls)

    def __enter__(self) -> Writer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def define(self, cls: type[Any], topic: str | None = None) -> str:
        """Announce a class (under ``topic``, default its first topic); returns the topic."""
        fmt = format_of(cls)
        topic = topic or (fmt.topics[0] if fmt.topics else fmt.name)
        if (cls, topic) in self._topics:
            return topic
        if self._started:
            raise ULogError(f"define {cls.__name__} ({topic}) before the first record: formats precede data")
        for name, f in {**fmt.formats(), topic: fmt.renamed(topic)}.items():
            if name == fmt.name and name != topic:
                continue  # the top-level format is written under its topic name only
            known = self._formats.get(name)
            if known is not None and known.text() != f.renamed(name).text():
                raise ULogError(f"two different formats named {name!r}")
            self._formats[name] = f.renamed(name)
        self._topics[(cls, topic)] = layout(fmt, {}).data_size
        return topic

    def _record(self, kind: str, body: bytes) -> None:
        if len(body) > 0xFFFF:
            raise ULogError(f"{kind!r} record of {len(body)} bytes exceeds 65535")
        self._buf += HEAD.pack(len(body), ord(kind))
        self._buf += body

    def _start(self) -> None:
        if self._started:
            return
        self._started = True
        self._buf += MAGIC + bytes((VERSION,)) + U64.pack(self._timestamp)
        self._record("B", bytes(16) + bytes(24))  # no flags, no appended data
        for key, value in self._info.items():
            self._record("I", _typed_value(key, value))
        for key, param in self._parameters.items():
            if isinstance(param, bool) or not isinstance(param, int | float):
                raise ULogError(f"parameter {key}: expected an int or float, got {param!r}")
            self._record("P", _typed_value(key, param))
        for fmt in self._formats.values():
            self._record("F", fmt.text().encode("utf-8"))

    def write(self, msg: Any, *, multi_id: int = 0, topic: str | None = None) -> None:
        """Append one record of a generated uORB message (instance ``multi_id`` of its topic)."""
        cls = type(msg)
        key = (cls, topic or "", multi_id)
        entry = self._ids.get(key)
        if entry is None:
            entry = self._subscribe(cls, topic, multi_id)
        data: bytes = msg.encode()
        self._buf += entry[0]
        self._buf += data[: entry[1]]
        if len(self._buf) >= 1 << 16:
            self.flush()

    def _subscribe(self, cls: type[Any], topic: str | None, multi_id: int) -> tuple[bytes, int]:
        if not 0 <= multi_id <= 255:
            raise ULogError(f"multi_id must be 0..255, got {multi_id}")
        if not self._started:
            name = self.define(cls, topic)
        else:
            fmt = format_of(cls)
            name = topic or (fmt.topics[0] if fmt.topics else fmt.name)
            if (cls, name) not in self._topics:
                raise ULogError(f"define {cls.__name__} ({name}) before the first record: formats precede data")
        self._start()
        msg_id = len(self._ids)
        if msg_id > 0xFFFF:
            raise ULogError("more than 65536 subscriptions")
        self._record("A", struct.pack("<BH", multi_id, msg_id) + name.encode("utf-8"))
        size = self._topics[(cls, name)]
        entry = (HEAD.pack(size + 2, ord("D")) + U16.pack(msg_id), size)
        self._ids[(cls, topic or "", multi_id)] = entry
        return entry

    def log(self, text: str, *, level: int = 6, timestamp: int = 0) -> None:
        """A logged text line ('L'); level 0..7 as syslog (6 = info)."""
        self._start()
        self._record("L", struct.pack("<BQ", ord("0") + level, timestamp) + text.encode("utf-8"))

    def flush(self) -> None:
        self._out.write(self._buf)
        self._buf.clear()

    def close(self) -> None:
        if self._closed:
            return
        self._start()
        self.flush()
        self._closed = True
        if self._owned:
            self._out.close()
        else:
            self._out.flush()


def write(
    target: str | os.PathLike[str] | BinaryIO,
    records: Iterable[Any],
    *,
    timestamp: int = 0,
    info: Mapping[str, str | int | float | bool] | None = None,
    messages: Iterable[type[Any]] = (),
) -> None:
    """Write ``records`` (generated uORB instances, or (instance, multi_id) pairs) as one ULog file."""
    items = list(records)
    classes = dict.fromkeys(messages)
    for item in items:
        classes[type(item[0] if isinstance(item, tuple) else item)] = None
    with Writer(target, timestamp=timestamp, info=info, messages=classes) as w:
        for item in items:
            if isinstance(item, tuple):
                w.write(item[0], multi_id=item[1])
            else:
                w.write(item)

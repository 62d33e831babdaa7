"""MAVLink payload helpers the generated message classes call: the codec errors, zero-filling,
text fields, the diagnosis of a value that does not fit its wire field, and batch decoding into
columns. Part of the MAVLink runtime that ``_mavlink`` re-exports.
"""

from __future__ import annotations

import importlib
import struct
from typing import Any, TypeAlias

BytesLike: TypeAlias = bytes | bytearray | memoryview


class DecodeError(ValueError):
    """Bytes that do not hold a valid message or frame; the message names what and where."""


class EncodeError(ValueError):
    """A value that does not fit its wire field, named as MESSAGE.field."""


def fill(data: BytesLike, size: int, name: str) -> bytes:
    """A payload zero-filled to ``size`` bytes (MAVLink 2 drops trailing zeros on send: most frames of a
    stream take this path, so the zeros come from a table)."""
    missing = size - len(data)
    if missing < 0:
        raise DecodeError(f"{name}: payload of {len(data)} bytes exceeds the maximum length {size}")
    return bytes(data) + _ZEROS[missing]


_ZEROS = [bytes(i) for i in range(256)]  # a MAVLink payload is at most 255 bytes


def text(raw: bytes) -> str:
    """A NUL-padded char[N] field as text (up to the first NUL)."""
    return raw.split(b"\x00", 1)[0].decode("utf-8", "surrogateescape")


def explain(name: str, obj: object, fields: tuple[tuple[str, str, str, int], ...]) -> EncodeError:
    """The first field of ``obj`` that does not fit the wire, as an EncodeError (the slow path)."""
    for ident, source, fmt, count in fields:
        value = getattr(obj, ident, None)
        where = f"{name}.{source}"
        if fmt == "s":
            if not isinstance(value, str):
                return EncodeError(f"{where}: expected text, got {value!r}")
            try:
                size = len(value.encode("utf-8", "surrogateescape"))
            except UnicodeError:
                return EncodeError(f"{where}: {value!r} cannot be encoded as UTF-8")
            if size > count:
                return EncodeError(f"{where}: {size} bytes exceed the capacity {count}")
        elif fmt == "B*":
            if not isinstance(value, bytes | bytearray) or len(value) != count:
                return EncodeError(f"{where}: expected {count} bytes, got {value!r}")
        elif count:
            if not isinstance(value, list | tuple) or len(value) != count:
                return EncodeError(f"{where}: expected a list of {count} values, got {value!r}")
            for i, item in enumerate(value):
                problem = _scalar_problem(fmt, item)
                if problem:
                    return EncodeError(f"{where}[{i}]: {problem}")
        else:
            problem = _scalar_problem(fmt, value)
            if problem:
                return EncodeError(f"{where}: {problem}")
    return EncodeError(f"{name}: cannot be encoded")


def _scalar_problem(fmt: str, value: object) -> str:
    if fmt in "fd":
        if isinstance(value, bool) or not isinstance(value, int | float):
            return f"expected a number, got {value!r}"
    elif isinstance(value, bool) or not isinstance(value, int):
        return f"expected an integer, got {value!r}"
    try:
        struct.pack("<" + fmt, value)
    except (struct.error, OverflowError):
        bits = struct.calcsize(fmt) * 8
        kind = "a float" if fmt in "fd" else ("a signed" if fmt.islower() else "an unsigned") + f" {bits}-bit integer"
        return f"{value!r} does not fit {kind}"
    return ""


def struct_columns(data: BytesLike, layout: struct.Struct, name: str) -> list[tuple[Any, ...]]:
    """Fixed-size records -> one tuple per struct item (iter_unpack, no object per record)."""
    if len(data) % layout.size:
        raise DecodeError(f"{name}: {len(data)} bytes are not a whole number of {layout.size}-byte records")
    if not data:
        return [()] * len(layout.unpack(bytes(layout.size)))
    return list(zip(*layout.iter_unpack(data), strict=True))


def numpy_columns(
    data: BytesLike, size: int, dtype: list[tuple[Any, ...]], use_numpy: bool | None, name: str
) -> dict[str, Any] | None:
    """Fixed-size records -> numpy columns, or None when numpy is not wanted or not installed."""
    if use_numpy is False:
        return None
    try:
        np: Any = importlib.import_module("numpy")
    except ImportError:
        if use_numpy:
            raise
        return None
    if len(data) % size:
        raise DecodeError(f"{name}: {len(data)} bytes are not a whole number of {size}-byte records")
    records = np.frombuffer(data, dtype=np.dtype(dtype))
    return {field[0]: records[field[0]].copy() for field in dtype}

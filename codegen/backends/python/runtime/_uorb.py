"""Run-time support of the generated uORB codecs: errors, C strings, batch decoding into columns.

Standard library only; numpy is used when a caller asks for it and it is installed.
"""

from __future__ import annotations

import importlib
import struct
from collections.abc import Sequence
from typing import Any


class DecodeError(ValueError):
    """Bytes that are not a record of the message: names the message or field and what was expected."""


class EncodeError(ValueError):
    """A value that does not fit its field: names the field path and the value."""


def cstr_encode(value: object, capacity: int, path: str) -> bytes:
    """A str as the bytes of a NUL-padded ``char[capacity]`` (struct pads the rest)."""
    if not isinstance(value, str):
        raise EncodeError(f"{path}: expected a str, got {value!r}")
    data = value.encode("utf-8")
    if len(data) > capacity:
        raise EncodeError(f"{path}: {len(data)} bytes of UTF-8 exceed capacity {capacity}")
    return data


def cstr_decode(data: bytes) -> str:
    """A NUL-padded char array as text: up to the first NUL, undecodable bytes replaced."""
    return data.split(b"\0", 1)[0].decode("utf-8", "replace")


def char_encode(value: object, path: str) -> bytes:
    """One ``char``: a str of at most one Latin-1 character ('' is NUL)."""
    if isinstance(value, str) and len(value) <= 1 and (not value or ord(value) < 256):
        return value.encode("latin-1") or b"\0"
    raise EncodeError(f"{path}: expected one Latin-1 character, got {value!r}")


def char_decode(data: bytes) -> str:
    return "" if data == b"\0" else data.decode("latin-1")


def fixed_bytes(value: object, size: int, path: str) -> bytes:
    """A ``uint8[size]`` value: exactly ``size`` bytes."""
    if isinstance(value, bytes | bytearray | memoryview) and len(value) == size:
        return bytes(value)
    raise EncodeError(f"{path}: expected {size} bytes, got {value!r}")


def nested(value: Any, cls: type[Any], path: str) -> bytes:
    """A nested message's own encoding (its errors re-named with the full field path)."""
    if not isinstance(value, cls):
        raise EncodeError(f"{path}: expected a {cls.__name__}, got {value!r}")
    try:
        data: bytes = value.encode()
    except EncodeError as exc:
        inner = str(exc)
        prefix = cls.__name__ + "."
        raise EncodeError(
            path + inner[len(cls.__name__) :] if inner.startswith(prefix) else f"{path}: {inner}"
        ) from None
    return data


def nested_array(value: Any, count: int, cls: type[Any], path: str) -> bytes:
    if not isinstance(value, list | tuple) or len(value) != count:
        raise EncodeError(f"{path}: expected a list of {count} {cls.__name__}, got {value!r}")
    return b"".join([nested(item, cls, f"{path}[{i}]") for i, item in enumerate(value)])


def encode_error(name: str, obj: object, table: Sequence[tuple[str, str, str, int]], exc: Exception) -> EncodeError:
    """The error for a failed pack: finds the plain field at fault (only runs on the error path)."""
    for attr, field, code, count in table:
        value = getattr(obj, attr, None)
        path = f"{name}.{field}"
        try:
            if count:
                if not isinstance(value, list | tuple) or len(value) != count:
                    return EncodeError(f"{path}: expected a list of {count} items, got {value!r}")
                struct.pack(f"<{count}{code}", *value)
            else:
                struct.pack("<" + code, value)
        except (struct.error, TypeError, OverflowError) as err:
            return EncodeError(f"{path}: {err} (value {value!r})")
    return EncodeError(f"{name}: {exc}")


_NUMPY: list[Any] = []


def numpy_module(use_numpy: bool | None) -> Any:
    """numpy when wanted and installed, else None (imported on first use: an optional extra).

    ``use_numpy``: None uses numpy if installed, True requires it, False never uses it.
    """
    if use_numpy is False:
        return None
    if not _NUMPY:
        try:
            _NUMPY.append(importlib.import_module("numpy"))
        except ImportError:
            _NUMPY.append(None)
    if _NUMPY[0] is None and use_numpy:
        raise ImportError("use_numpy=True needs numpy, which is not installed")
    return _NUMPY[0]


def layout_format(codes: Sequence[str], offsets: Sequence[int], sizes: Sequence[int]) -> str:
    """Struct format reading values at ``offsets`` (gaps skipped) up to the end of the last one."""
    items: list[str] = ["<"]
    at = 0
    for code, offset, size in zip(codes, offsets, sizes, strict=True):
        if offset < at:
            raise DecodeError(f"overlapping values at offset {offset}")
        if offset > at:
            items.append(f"{offset - at}x")
        items.append(code)
        at = offset + size
    return "".join(items)


class Columns:
    """Batch decoding of back-to-back fixed-size records into one column per value.

    ``fmt`` reads the values from the start of a record up to the end of the last value; a record
    is ``size`` bytes unless a call gives another ``stride`` (ULog data drops trailing padding).
    """

    __slots__ = ("_dtypes", "_structs", "fmt", "minimum", "names", "np_types", "offsets", "size")

    def __init__(
        self, names: tuple[str, ...], fmt: str, size: int, np_types: tuple[str, ...], offsets: tuple[int, ...]
    ) -> None:
        self.names = names
        self.fmt = fmt
        self.size = size
        self.np_types = np_types
        self.offsets = offsets
        self.minimum = struct.calcsize(fmt)
        self._structs: dict[int, struct.Struct] = {}
        self._dtypes: dict[int, Any] = {}

    def record_struct(self, stride: int) -> struct.Struct:
        s = self._structs.get(stride)
        if s is None:
            if stride < self.minimum:
                raise DecodeError(f"records of {stride} bytes are shorter than the {self.minimum} the values need")
            s = struct.Struct(self.fmt + (f"{stride - self.minimum}x" if stride > self.minimum else ""))
            self._structs[stride] = s
        return s

    def dtype(self, np: Any, stride: int) -> Any:
        d = self._dtypes.get(stride)
        if d is None:
            self.record_struct(stride)  # same length check
            spec = {"names": list(self.names), "formats": list(self.np_types), "offsets": list(self.offsets)}
            d = np.dtype({**spec, "itemsize": stride})
            self._dtypes[stride] = d
        return d

    def count(self, buffer: bytes, stride: int) -> int:
        n, rest = divmod(len(buffer), stride)
        if rest:
            raise DecodeError(f"{len(buffer)} bytes are not a whole number of {stride}-byte records")
        return n

    def decode(
        self, buffer: bytes, stride: int | None = None, *, use_numpy: bool | None = None, copy: bool = True
    ) -> dict[str, Any]:
        """{column: values} of every record in ``buffer``: numpy arrays (see :func:`numpy_module`),
        else lists."""
        stride = self.size if stride is None else stride
        if stride <= 0:
            raise DecodeError(f"expected a positive record size, got {stride}")
        n = self.count(buffer, stride)
        np = numpy_module(use_numpy)
        if np is not None:
            rows = np.frombuffer(buffer, dtype=self.dtype(np, stride), count=n)
            if not copy:
                return {name: rows[name] for name in self.names}
            # Copy block by block: each block of records stays in cache while every column takes
            # its share (a whole-column strided copy per field runs ~2x slower on large buffers).
            out = {name: np.empty(n, dtype=rows.dtype.fields[name][0]) for name in self.names}
            block = max(64, (1 << 19) // stride)
            for start in range(0, n, block):
                chunk = rows[start : start + block]
                for name, column in out.items():
                    column[start : start + block] = chunk[name]
            return out
        s = self.record_struct(stride)
        if not n:
            return {name: [] for name in self.names}
        return dict(zip(self.names, map(list, zip(*s.iter_unpack(buffer), strict=False)), strict=True))

"""numpy columns and Python text as Arrow arrays, built from their buffers.

pyarrow's ``pa.array`` (and ``pa.scalar``) first asks whether its input is a pandas object, and asking imports
pandas: 0.3-0.6 s of a fresh process, more than the whole export of a flight log's battery records, although no
pandas object ever reaches it here. ``Array.from_buffers`` over the numpy memory itself (and a validity bitmap
where something is null) makes the same arrays without asking: the values are numpy's, unknown is null, and a
value its Arrow type cannot hold is a ValueError, as ``pa.array``'s safe cast raises (``ArrowInvalid``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import pyarrow as pa

from ..battery.columns import NDArray

# the numpy type of an Arrow primitive's buffer, by the Arrow type's name (a timestamp's is int64)
_BUFFER = {
    "int8": np.int8,
    "int16": np.int16,
    "int32": np.int32,
    "int64": np.int64,
    "uint8": np.uint8,
    "uint16": np.uint16,
    "uint32": np.uint32,
    "uint64": np.uint64,
    "float": np.float32,
    "double": np.float64,
}
_OFFSET_LIMIT = (1 << 31) - 1  # a string array's int32 offsets


def _validity(null: NDArray | None, n: int) -> tuple[Any, int]:
    """The validity bitmap (LSB first, as Arrow's) and the null count; no bitmap where nothing is null."""
    if null is None:
        return None, 0
    null = np.asarray(null, bool)
    if len(null) != n:
        raise ValueError(f"expected a null mask of {n} rows, got {len(null)}")
    count = int(np.count_nonzero(null))
    if not count:
        return None, 0
    return pa.py_buffer(np.packbits(~null, bitorder="little")), count


def _buffer_values(values: NDArray, dtype: Any, typ: Any, null: NDArray | None) -> NDArray:
    """``values`` as ``dtype``, contiguous; a value that changes in a cast to integers (where not null) is refused,
    and floats are narrowed as Arrow's safe cast narrows them (1e300 as a float32 is infinity)."""
    values = np.asarray(values)
    if values.dtype == dtype:
        return np.ascontiguousarray(values)
    with np.errstate(invalid="ignore", over="ignore"):  # NaN into integers is refused below; 1e300 is inf
        cast = np.ascontiguousarray(values.astype(dtype, casting="unsafe"))
    if dtype.kind in "iu" and not np.can_cast(values.dtype, dtype, "safe"):  # Arrow narrows floats unchecked
        with np.errstate(invalid="ignore"):
            changed = cast != values
        if null is not None:
            changed &= ~np.asarray(null, bool)
        if changed.any():
            bad = values[np.flatnonzero(changed)[0]]
            raise ValueError(f"{bad!r} does not fit the Arrow type {typ}")
    return cast


def array(values: NDArray, typ: Any, null: NDArray | None = None) -> Any:
    """A 1-D numpy array as an Arrow array of the primitive (or timestamp) type ``typ``, null where ``null``.
    The numpy memory is the array's (no copy) when it already has the type's layout."""
    n = len(values)
    validity, nulls = _validity(null, n)
    if pa.types.is_boolean(typ):
        data = pa.py_buffer(np.packbits(np.asarray(values, bool), bitorder="little"))
    else:
        name = "int64" if pa.types.is_timestamp(typ) else str(typ)
        data = pa.py_buffer(_buffer_values(values, np.dtype(_BUFFER[name]), typ, null))
    return pa.Array.from_buffers(typ, n, [validity, data], null_count=nulls)


def strings(values: Sequence[str | bytes | None], null: NDArray | None = None) -> Any:
    """Python text as an Arrow string array; null for None (and where ``null``). Bytes must be UTF-8."""
    n = len(values)
    none = np.fromiter((v is None for v in values), bool, n)
    if null is not None:
        none |= np.asarray(null, bool)
    encoded = [b"" if skip else _utf8(v) for v, skip in zip(values, none.tolist(), strict=True)]
    offsets = np.zeros(n + 1, np.int64)
    np.cumsum(np.fromiter(map(len, encoded), np.int64, n), out=offsets[1:])
    if offsets[-1] > _OFFSET_LIMIT:
        raise ValueError(f"{offsets[-1]} bytes of text do not fit one Arrow string array")
    validity, nulls = _validity(none, n)
    buffers = [validity, pa.py_buffer(offsets.astype(np.int32)), pa.py_buffer(b"".join(encoded))]
    return pa.Array.from_buffers(pa.string(), n, buffers, null_count=nulls)


def repeat(text: str, n: int) -> Any:
    """``text`` ``n`` times as a plain string array."""
    data = text.encode("utf-8")
    if len(data) * n > _OFFSET_LIMIT:
        raise ValueError(f"{len(data) * n} bytes of text do not fit one Arrow string array")
    offsets = np.arange(n + 1, dtype=np.int32) * np.int32(len(data))
    return pa.Array.from_buffers(pa.string(), n, [None, pa.py_buffer(offsets), pa.py_buffer(data * n)])


def _utf8(value: str | bytes | None) -> bytes:
    if isinstance(value, bytes):
        value.decode("utf-8")  # refused as pa.array refuses it: a UnicodeDecodeError (a ValueError)
        return value
    if not isinstance(value, str):
        raise TypeError(f"expected text, got {type(value).__name__}")
    return value.encode("utf-8")

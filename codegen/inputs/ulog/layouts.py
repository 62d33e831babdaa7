"""An older ULog layout translated to the generated class over whole columns: what the generated
per-record decoder (``_ulog.Log.decoder``'s ``decode_other``) does to one record, done to every
record of a chunk at once with numpy.

Fields are matched by name (through PX4's renames), compatible retypes converted with the same
range check (a value that does not fit keeps the class's default), array sizes padded with the
default or truncated, and fields the log lacks or types otherwise keep the class's default. The
per-record decoder stays the oracle: tests/apps/test_export_columnar.py compares both on every
real ULog of ../shared and on synthetic older layouts.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..model import FormatDiff

NDArray = Any  # numpy arrays

# ULog C type -> numpy type (the class's column type)
_NP = {
    "int8_t": "i1", "uint8_t": "u1", "int16_t": "i2", "uint16_t": "u2", "int32_t": "i4", "uint32_t": "u4",
    "int64_t": "i8", "uint64_t": "u8", "float": "f4", "double": "f8", "bool": "?",
}  # fmt: skip
_FLOAT32_MAX = 3.4028234663852886e38


@dataclass(frozen=True)
class Conversion:
    """A field of another but compatible type: the log's field ``log`` read, range-checked and cast."""

    name: str  # schema name
    log: str  # the log's name for it
    schema_type: str  # as ULog spells it: uint8_t, float[14]
    log_type: str


def plan(diff: FormatDiff) -> tuple[dict[str, str], dict[str, Conversion]]:
    """(schema name -> log name of the fields read as they are, schema name -> conversion)."""
    alias = {new: old for old, new in diff.renamed}
    converted = {r.name: Conversion(r.name, alias.get(r.name, r.name), r.schema, r.log) for r in diff.converted}
    return alias, converted


def _split(type_text: str) -> tuple[str, int]:
    base, _, count = type_text.partition("[")
    return base, int(count.rstrip("]") or 0)


def supported(conv: Conversion) -> bool:
    return _split(conv.schema_type)[0] in _NP and _split(conv.log_type)[0] in _NP


def convert(conv: Conversion, values: NDArray, default: Any) -> NDArray:
    """The log's column ``values`` as the class holds it, as ``_ulog_compare.convert`` does record by
    record: a value that fits the schema's type cast to it, any other the class's default; array
    elements beyond the log's length the default, beyond the class's dropped."""
    import numpy as np

    base, count = _split(conv.schema_type)
    code = _NP[base]
    code = "f" if code == "f4" else code
    n = len(values)
    # a float field converted from another type holds the value as the decoder's Python float does
    out_type = np.dtype(("f8" if _split(conv.log_type)[0] != "float" else "f4") if code == "f" else code)
    fits = _fits(code)
    if not count:
        ok = fits(values)
        out = np.full(n, default, out_type)
        out[ok] = values[ok].astype(out_type)
        return out
    out = np.tile(np.asarray(default, out_type), (n, 1))
    width = min(count, values.shape[1] if values.ndim == 2 else 0)
    part = values[:, :width]
    ok = fits(part)
    target = out[:, :width]
    target[ok] = part[ok].astype(out_type)
    return out


def _fits(code: str) -> Callable[[NDArray], NDArray]:
    """Whether each value fits the schema's type (``_ulog_compare._fits``; NaN and infinities fit a float)."""
    import numpy as np

    if code == "f":
        return lambda x: ~np.isfinite(x) | (np.abs(x.astype(np.float64)) <= _FLOAT32_MAX)
    if code == "f8":
        return lambda x: np.ones(x.shape, bool)
    lo, hi = (0, 1) if code == "?" else (int(np.iinfo(np.dtype(code)).min), int(np.iinfo(np.dtype(code)).max))

    def fits(x: NDArray) -> NDArray:
        x = x.view(np.uint8) if x.dtype.kind == "b" else x
        if x.dtype.kind == "u":  # never below lo (<= 0)
            return x <= hi if hi < int(np.iinfo(x.dtype).max) else np.ones(x.shape, bool)
        ok = x >= lo if lo > int(np.iinfo(x.dtype).min) else np.ones(x.shape, bool)
        return ok & (x <= hi) if hi < int(np.iinfo(x.dtype).max) else ok

    return fits

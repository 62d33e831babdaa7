"""JSON Lines for ``battgen convert`` at the speed of the data: records written with orjson where its bytes are
the standard library's, the standard library everywhere else.

Reading is :func:`...inputs.jsonl_blocks.loads_line`, the one rule of when orjson reads a line as json does.

Writing: :func:`encode_record` returns the bytes ``json.dumps(record, allow_nan=False)`` writes, by
``orjson.dumps`` (10x faster) where its bytes can be told to be json's but for the separators (its docstring).

Without orjson installed writing falls back to the standard library whole.
"""

from __future__ import annotations

import dataclasses
import json
import re
from typing import Any, cast

try:
    import orjson
except ImportError:  # pragma: no cover - a dependency; the standard library alone still gives the same bytes
    orjson = None  # type: ignore[assignment]

# ------------------------------------------------------------------------------------------------
# writing

_SAFE_KEY = re.compile(r'[^"\\,:\x00-\x1f\x7f-\U0010ffff]*')  # spelled alike by both, no separator inside
_ENCODE = json.JSONEncoder(allow_nan=False).encode  # built once: json.dumps builds one a call for allow_nan
_key_es: dict[tuple[object, ...], int] = {}  # per key tuple (one or two a run): the e's in its keys, -1 unsafe


def _es_in_keys(keys: tuple[object, ...]) -> int:
    """How many ``e`` the keys hold (to tell a number's exponent from them), or -1 when a key is not text
    both spell alike or holds ``true``/``false`` (whose e's are counted as values')."""
    found = _key_es.get(keys)
    if found is None:
        found = -1
        if all(k.__class__ is str and _SAFE_KEY.fullmatch(k) and "true" not in k and "false" not in k for k in keys):
            found = sum(cast(str, k).count("e") for k in keys)
        if len(_key_es) < 256:
            _key_es[keys] = found
    return found


_INTEGRAL = frozenset({"int", "list[int]", "bool", "list[bool]"})
_integral: dict[type, bool] = {}


def integral(cls: type) -> bool:
    """Whether every field of a generated message class holds integers or booleans (its dataclass fields are typed
    ``int``, ``bool`` or lists of them, as MAVLink's are): orjson then writes json's very digits, and its line needs
    no check but the separators (:func:`integral_line`)."""
    found = _integral.get(cls)
    if found is None:
        found = dataclasses.is_dataclass(cls) and all(f.type in _INTEGRAL for f in dataclasses.fields(cls))
        _integral[cls] = found
    return found


def integral_line(record: dict[str, Any]) -> bytes | None:
    """``json.dumps(record, allow_nan=False)``'s bytes and a newline for the plain data of an :func:`integral` class
    (keys that are field names, so no separator inside one), or None (orjson refuses an integer beyond 64 bits)."""
    if orjson is None:
        return None
    try:
        out = orjson.dumps(record, option=orjson.OPT_APPEND_NEWLINE)
    except TypeError:
        return None
    return out.replace(b",", b", ").replace(b":", b": ")


def orjson_line(record: dict[Any, Any]) -> bytes | None:
    """``json.dumps(record, allow_nan=False)``'s bytes and a newline when orjson can be seen to write them, else
    None.

    orjson writes them when what it wrote is what json writes but for the separators: a flat object of numbers,
    booleans and lists of them -- no text beside the keys (two quotes a key), no ``null`` (NaN and the
    infinities are orjson's null, json refuses them), no exponent (no ``e`` beyond the keys' and the booleans'),
    no ``0.0000`` (a float below 1e-4, which json writes with an exponent); widened to json's ``", "`` and
    ``": "``, since no comma or colon is in a key. What passes is also strict JSON data as it is."""
    if orjson is None:
        return None
    es = _es_in_keys(tuple(record))
    if es < 0:
        return None
    try:
        out = orjson.dumps(record, option=orjson.OPT_APPEND_NEWLINE)
    except TypeError:  # an integer beyond 64 bits, a type json refuses or writes otherwise
        return None
    if (
        out.count(b'"') == 2 * len(record)
        and b"null" not in out
        and b"0.0000" not in out
        and out.count(b"e") == es + out.count(b"true") + out.count(b"false")
    ):
        return out.replace(b",", b", ").replace(b":", b": ")
    return None


def encode_record(record: Any) -> bytes:
    """One JSON Lines record: ``json.dumps(record, allow_nan=False)``'s bytes and a newline, by orjson where
    :func:`orjson_line` can tell they are the same, else by json."""
    if record.__class__ is dict:
        out = orjson_line(record)
        if out is not None:
            return out
    return _ENCODE(record).encode() + b"\n"

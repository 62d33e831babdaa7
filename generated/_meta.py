# Copied by battgen from codegen/backends/python/runtime/_meta.py; do not edit here, edit it there.
"""Run-time support shared by the generated modules: field metadata and reading plain data.

Standard library only, so the generated package can be vendored as it is.
"""

from __future__ import annotations

import math
import reprlib
import types
from collections.abc import Callable, Mapping
from typing import Any, TypeVar

T = TypeVar("T")


class _Brief(reprlib.Repr):
    """repr() kept to a line: a hostile value (a YAML alias bomb expands to billions of items, an integer
    of 5,000 digits has no repr at all) is quoted by its start, never walked or printed whole."""

    def __init__(self) -> None:
        super().__init__()
        self.maxlevel = 2
        self.maxstring = self.maxother = 60
        self.maxlong = 40

    def repr_int(self, x: int, level: int) -> str:
        if x.bit_length() > 128:  # repr() refuses over 4,300 digits
            return f"{'-' if x < 0 else ''}<an integer of {int(x.bit_length() * 0.30103) + 1} digits>"
        return super().repr_int(x, level)

    def repr_str(self, x: str, level: int) -> str:
        return super().repr_str(x[:200], level) + ("..." if len(x) > 200 else "")


brief = _Brief().repr

PATH_WIDTH = 160  # codegen.text.brief.PATH_WIDTH: the tool cuts a path the same way


def clip(path: str) -> str:
    """A path as a message shows it: whole up to PATH_WIDTH characters, else its head and tail (a data
    key, such as a devicetree pattern property's name, can be thousands of characters)."""
    if len(path) <= PATH_WIDTH:
        return path
    tail = PATH_WIDTH // 3
    return path[: PATH_WIDTH - tail - 3] + "..." + path[-tail:]


class DataError(ValueError):
    """Input data that does not fit a message: names the field path, what was expected and the value."""

    def __init__(self, path: str, expected: str, value: object) -> None:
        super().__init__(f"{clip(path)}: expected {expected}, got {brief(value)}")
        self.path = path
        self.expected = expected
        self.value = value


def meta(
    *,
    name: str,
    type: str,
    unit: str | None = None,
    quantity: str | None = None,
    scale: float = 1.0,
    offset: float = 0.0,
    minimum: float | None = None,
    maximum: float | None = None,
    invalid: float | None = None,
    invalid_text: str | None = None,
    per_element: bool = False,
    first_decides: bool = False,
    enums: tuple[str, ...] = (),
    extension: bool = False,
    pattern: str | None = None,
    doc: str = "",
) -> Mapping[str, Any]:
    """The read-only metadata of one field, found at ``dataclasses.fields(cls)[i].metadata``."""
    return types.MappingProxyType(
        {
            "name": name,
            "type": type,
            "unit": unit,
            "quantity": quantity,
            "scale": scale,
            "offset": offset,
            "minimum": minimum,
            "maximum": maximum,
            "invalid": invalid,
            "invalid_text": invalid_text,
            "per_element": per_element,
            "first_decides": first_decides,  # MAVLink [X:]: the array is unknown when element 0 is the sentinel
            "enums": enums,
            "extension": extension,
            "pattern": pattern,
            "doc": doc,
        }
    )


def is_sentinel(value: object, invalid: float | None) -> bool:
    """True when ``value`` equals the sentinel ``invalid`` (NaN matches NaN)."""
    if invalid is None:
        return False
    if isinstance(invalid, float) and math.isnan(invalid):
        return isinstance(value, float) and math.isnan(value)
    return bool(value == invalid)


def _same(a: object, b: object) -> bool:
    if a is b:
        return True
    if isinstance(a, float) and isinstance(b, float):
        return a == b or (a != a and b != b)  # NaN: the same "unknown"
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    return bool(a == b)


def same_message(a: object, b: object) -> bool:
    """Field-by-field equality of two messages of one class, NaN equal to NaN."""
    names: tuple[str, ...] = getattr(type(a), "__slots__", ())
    return all(_same(getattr(a, name), getattr(b, name)) for name in names)


def as_int(value: object, path: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        if isinstance(value, float) and value.is_integer():
            return int(value)
        raise DataError(path, "an integer", value)
    return value


def as_float(value: object, path: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        if isinstance(value, str) and value in ("NaN", "Infinity", "-Infinity", "nan", "inf", "-inf"):
            return float(value)
        raise DataError(path, "a number", value)
    try:
        return float(value)
    except OverflowError:  # an integer beyond the largest double
        raise DataError(path, "a number within the float range", value) from None


def as_bool(value: object, path: str) -> bool:
    if isinstance(value, bool):
        return value
    if isinstance(value, int | float) and value in (0, 1):  # JSON writers may emit 1.0 for true
        return bool(value)
    raise DataError(path, "true or false", value)


def as_str(value: object, path: str) -> str:
    if not isinstance(value, str):
        raise DataError(path, "a string", value)
    return value


def _check_length(n: int, path: str, capacity: int | None, fixed: bool, value: object) -> None:
    if capacity is None:
        return
    if fixed and n != capacity:
        raise DataError(path, f"exactly {capacity} items", value)
    if n > capacity:
        raise DataError(path, f"at most {capacity} items", value)


def as_bytes(value: object, path: str, capacity: int | None, fixed: bool) -> bytes:
    if isinstance(value, str):
        data = value.encode("utf-8")
    elif isinstance(value, bytes | bytearray):
        data = bytes(value)
    elif isinstance(value, list | tuple):
        items = [as_int(v, f"{path}[{i}]") for i, v in enumerate(value)]
        for i, v in enumerate(items):
            if not 0 <= v <= 255:
                raise DataError(f"{path}[{i}]", "a byte (0..255)", v)
        data = bytes(items)
    else:
        raise DataError(path, "bytes, a string or a list of byte values", value)
    _check_length(len(data), path, capacity, fixed, value)
    return data


def as_list(value: object, path: str, capacity: int | None, fixed: bool, item: Callable[[object, str], T]) -> list[T]:
    if not isinstance(value, list | tuple):
        raise DataError(path, "a list", value)
    _check_length(len(value), path, capacity, fixed, value)
    return [item(v, f"{path}[{i}]") for i, v in enumerate(value)]


def as_typed_list(
    value: object, path: str, capacity: int | None, fixed: bool, kind: type[T], item: Callable[[object, str], T]
) -> list[T]:
    """:func:`as_list` of ``item``, with a fast pass for what JSON gives: a list of the right length whose
    elements are all exactly ``kind`` (so ``item`` would hand each back unchanged); anything else takes
    :func:`as_list`, which builds an element's path only to name it."""
    if isinstance(value, list):
        n = len(value)
        if capacity is None or n == capacity or (n < capacity and not fixed):
            for v in value:
                if v.__class__ is not kind:
                    break
            else:
                return value[:]
    return as_list(value, path, capacity, fixed, item)


def as_object(value: object, path: str, cls: Any) -> Any:
    if not isinstance(value, Mapping):
        raise DataError(path, "an object", value)
    try:
        result = cls.from_dict(value)
    except DataError as exc:
        raise DataError(f"{path}.{exc.path}", exc.expected, exc.value) from None
    return result


def check_keys(
    data: object, known: frozenset[str], patterns: tuple[tuple[str, str], ...], cls: str
) -> Mapping[str, Any]:
    """The data as a mapping, after checking it names only fields of ``cls``."""
    if not isinstance(data, Mapping):
        raise DataError(cls, "an object", data)
    for key in data:
        if key not in known and not any(_match(p, key) for p, _ in patterns):
            name = key if isinstance(key, str) and len(key) <= 80 else brief(key)  # a name, not a novel
            raise DataError(f"{cls}.{name}", "a field of " + cls, data[key])
    return data


def _match(pattern: str, key: object) -> bool:
    import re

    return isinstance(key, str) and re.search(pattern, key) is not None

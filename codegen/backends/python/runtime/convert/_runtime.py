"""Run-time support of the generated converters: the loss report, float32/float16 emulation,
C integer conversions as a Cortex-M performs them, and the few array algorithms the mappings
name live in ``_cells.py``.

Standard library only: this file is copied verbatim into ``generated/convert/_runtime.py``.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Iterator
from typing import Any


class ConversionError(ValueError):
    """A conversion that cannot be made (a policy with no behaviour for the pair, bad input)."""


class LossEntry:
    """One thing that did not survive a conversion: ``kind`` is ``unknown`` (a target field left
    at its invalid value), ``dropped`` (source information with no place in the target),
    ``clamped`` (a value forced into range), ``rounded`` (a value quantised) or ``unrepresentable``
    (a source value the target cannot hold, written as the target's "unknown" instead: a NaN cell
    voltage becomes UINT16_MAX -- where a converter once refused the whole record)."""

    __slots__ = ("detail", "field", "kind")

    def __init__(self, kind: str, field: str, detail: str = "") -> None:
        self.kind = kind
        self.field = field
        self.detail = detail

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, LossEntry):
            return NotImplemented
        return (self.kind, self.field, self.detail) == (other.kind, other.field, other.detail)

    def __hash__(self) -> int:
        return hash((self.kind, self.field, self.detail))

    def __repr__(self) -> str:
        return f"LossEntry({self.kind!r}, {self.field!r}, {self.detail!r})"

    def to_dict(self) -> dict[str, str]:
        out = {"kind": self.kind, "field": self.field}
        if self.detail:
            out["detail"] = self.detail
        return out


class LossReport:
    """What a conversion lost, in the order it happened (each entry once).

    Entries are kept as (kind, field, detail) keys of an insertion-ordered dict; the
    :class:`LossEntry` objects are made when asked for, so a conversion only pays for a dict store."""

    __slots__ = ("_keys", "carried", "full")

    def __init__(self, *, full: bool = True) -> None:
        self._keys: dict[tuple[str, str, str], None] = {}
        # False: only what happens to values (clamped, rounded, unrepresentable) is recorded, not the fields
        # dropped or left unknown, which every record of a pair loses alike (a converter then skips finding them)
        self.full = full
        # what a firmware keeps between messages at a precision its output does not show (ArduPilot's
        # consumed charge is a float, BATTERY_STATUS sends whole mAh): the next message's <name>_before
        self.carried: dict[str, float] = {}

    def carry(self, name: str, value: float) -> None:
        self.carried[name] = value

    @property
    def entries(self) -> list[LossEntry]:
        return [LossEntry(*key) for key in self._keys]

    def add(self, kind: str, field: str, detail: str = "") -> None:
        self._keys[(kind, field, detail)] = None

    def unknown(self, field: str, detail: str = "") -> None:
        self._keys[("unknown", field, detail)] = None

    def dropped(self, field: str, detail: str = "") -> None:
        self._keys[("dropped", field, detail)] = None

    def clamped(self, field: str, detail: str = "") -> None:
        self._keys[("clamped", field, detail)] = None

    def rounded(self, field: str, detail: str = "") -> None:
        self._keys[("rounded", field, detail)] = None

    def unrepresentable(self, field: str, detail: str = "") -> None:
        self._keys[("unrepresentable", field, detail)] = None

    def discard(self, kind: str, field: str) -> None:
        """Withdraw entries (a later rule filled a field an earlier one left unknown)."""
        self._keys = {k: None for k in self._keys if not (k[0] == kind and k[1] == field)}

    def fields(self, kind: str) -> list[str]:
        return [k[1] for k in self._keys if k[0] == kind]

    def details(self, kind: str) -> list[tuple[str, str]]:
        """(field, detail) of each entry of ``kind``; no entry objects made (convert asks it of every record)."""
        return [(k[1], k[2]) for k in self._keys if k[0] == kind] if self._keys else []

    def to_dict(self) -> list[dict[str, str]]:
        return [e.to_dict() for e in self.entries]

    def summary(self) -> str:
        """A short text: one line per kind, fields grouped by message (``uorb.BatteryStatus: a, b``)."""
        if not self._keys:
            return "nothing lost"
        lines = []
        for kind in dict.fromkeys(k[0] for k in self._keys):
            groups: dict[str, list[str]] = {}
            for k, field, detail in self._keys:
                if k == kind:
                    owner, _, name = field.rpartition(".")
                    groups.setdefault(owner, []).append(f"{name} ({detail})" if detail else name)
            count = sum(len(v) for v in groups.values())
            parts = "; ".join(
                f"{owner}: {', '.join(names)}" if owner else ", ".join(names) for owner, names in groups.items()
            )
            lines.append(f"{kind} ({count}): {parts}")
        return "\n".join(lines)

    def __iter__(self) -> Iterator[LossEntry]:
        return iter(self.entries)

    def __len__(self) -> int:
        return len(self._keys)

    def __repr__(self) -> str:
        return f"LossReport({self.entries!r})"


# -- floating point -------------------------------------------------------------------------

_F32 = struct.Struct("<f")
_F16 = struct.Struct("<e")
F16_MAX = 65504.0


_F32_PACK, _F32_UNPACK = _F32.pack, _F32.unpack
_F16_PACK, _F16_UNPACK = _F16.pack, _F16.unpack


def f32(x: float) -> float:
    """``x`` rounded to IEEE float32, as a C ``float`` holds it (overflow becomes infinity)."""
    try:
        result: float = _F32_UNPACK(_F32_PACK(x))[0]
    except OverflowError:
        return math.copysign(math.inf, x)
    return result


def f32_div(a: float, b: float) -> float:
    """C's float ``a / b``: a zero divisor gives infinity of the quotient's sign, or NaN for 0 / 0."""
    if b == 0.0:
        if a != a or a == 0.0:
            return math.nan
        return math.copysign(math.inf, a) * math.copysign(1.0, b)
    return f32(a / b)


def f16(x: float, rep: LossReport | None, label: str) -> float:
    """``x`` as a saturated IEEE float16 holds it (DroneCAN ``float16``): finite values beyond
    the range clamp to +-65504, the rest round to nearest even."""
    if -F16_MAX <= x <= F16_MAX:  # the usual case first (NaN fails the test and is kept below)
        y: float = _F16_UNPACK(_F16_PACK(x))[0]
        if rep is not None and y != x:
            rep.rounded(label, "float16")
        return y
    if math.isnan(x) or math.isinf(x):
        return x
    if rep is not None:  # finite beyond the range
        rep.clamped(label, f"{x!r} beyond float16")
    return math.copysign(F16_MAX, x)


def roundf(x: float) -> float:
    """C ``roundf``: halves away from zero."""
    if math.isnan(x) or math.isinf(x):
        return x
    return math.copysign(math.floor(abs(x) + 0.5), x)


def is_marker(value: Any, marker: float) -> bool:
    if isinstance(marker, float) and math.isnan(marker):
        return isinstance(value, float) and math.isnan(value)
    return bool(value == marker)


def differs(a: Any, b: Any) -> bool:
    """``a != b`` with NaN equal to NaN (elementwise for lists)."""
    if isinstance(a, float) and isinstance(b, float):
        return not (a == b or (math.isnan(a) and math.isnan(b)))
    if isinstance(a, list | tuple) and isinstance(b, list | tuple):
        return len(a) != len(b) or any(differs(x, y) for x, y in zip(a, b, strict=True))
    return bool(a != b)


# -- integers -------------------------------------------------------------------------------


def to_int(x: float, lo: int, hi: int, rep: LossReport | None, label: str) -> int:
    """The nearest integer (halves away from zero) clamped into [lo, hi]; reports what it changed."""
    if math.isnan(x):
        raise ConversionError(f"{label}: NaN has no integer value")
    if math.isinf(x):  # out of range like any finite excess: clamped, and said so
        if rep is not None:
            rep.clamped(label, f"{x!r} outside {lo}..{hi}")
        return hi if x > 0 else lo
    n = int(math.copysign(math.floor(abs(x) + 0.5), x))
    if n < lo or n > hi:
        clamped = lo if n < lo else hi
        if rep is not None:
            rep.clamped(label, f"{x!r} outside {lo}..{hi}")
        return clamped
    if rep is not None and abs(n - x) > 1e-9 * max(1.0, abs(x)):
        rep.rounded(label, "to a whole unit")
    return n


def c_wrap(value: int, bits: int, signed: bool) -> int:
    """What a C integer of ``bits`` keeps of ``value`` (two's complement)."""
    value &= (1 << bits) - 1
    if signed and value >= 1 << (bits - 1):
        value -= 1 << bits
    return value


def c_float_to_int(x: float, bits: int, signed: bool, rep: LossReport | None = None, label: str = "") -> int:
    """A C float-to-integer assignment as a Cortex-M FPU performs it (VCVT): truncate toward
    zero, saturate to 32 bits (NaN gives 0), then keep the field's low ``bits``."""
    # the usual value first: finite and inside the 32-bit range, so truncated as it is (one int(), no NaN test)
    if (-2147483648.0 < x < 2147483648.0) if signed else (0.0 < x < 4294967296.0):
        n = int(x)
        out = n & ((1 << bits) - 1)
        if signed and out >= 1 << (bits - 1):
            out -= 1 << bits
        if rep is not None and out != n:
            rep.clamped(label, f"{x!r} does not fit {'int' if signed else 'uint'}{bits}")
        return out
    if math.isnan(x):
        n = 0
    elif signed:
        n = -(1 << 31) if x <= -(2.0**31) else (1 << 31) - 1 if x >= 2.0**31 else int(x)
    else:
        n = 0 if x <= 0 else (1 << 32) - 1 if x >= 2.0**32 else int(x)
    out = c_wrap(n, bits, signed)
    if rep is not None and not math.isnan(x) and out != (int(x) if math.isfinite(x) else None):
        rep.clamped(label, f"{x!r} does not fit {'int' if signed else 'uint'}{bits}")
    return out


def c_div(a: int, b: int) -> int:
    """C integer division (truncates toward zero)."""
    q = abs(a) // abs(b)
    return -q if (a < 0) != (b < 0) else q


def saturate(value: int, lo: int, hi: int) -> int:
    return lo if value < lo else hi if value > hi else value


# -- text -----------------------------------------------------------------------------------


def text_in(value: Any) -> str | None:
    """A text field's content (bytes are UTF-8, NUL padding dropped); empty means unknown."""
    if isinstance(value, bytes | bytearray):
        value = bytes(value).split(b"\x00", 1)[0].decode("utf-8", "replace")
    return value or None


def text_out(text: str, capacity: int | None, rep: LossReport | None, label: str) -> str:
    """A text for a string field of ``capacity`` bytes (a MAVLink ``char[N]``): cut to what the field holds, as the
    wire carries it, and reported clamped, as :func:`bytes_out` does for a byte array. A cut inside a character
    keeps its bytes (the model's strings decode a field's bytes with ``surrogateescape``)."""
    if capacity is None:
        return text
    data = text.encode("utf-8", "surrogateescape")
    if len(data) <= capacity:
        return text
    if rep is not None:
        rep.clamped(label, f"{len(data)} bytes, room for {capacity}")
    return data[:capacity].decode("utf-8", "surrogateescape")


def bytes_out(text: str, capacity: int | None, rep: LossReport | None, label: str) -> bytes:
    data = text.encode("utf-8")
    if capacity is not None and len(data) > capacity:
        if rep is not None:
            rep.clamped(label, f"{len(data)} bytes, room for {capacity}")
        data = data[:capacity]
    return data

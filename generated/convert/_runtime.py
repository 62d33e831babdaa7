# Copied by battgen from codegen/backends/python/runtime/convert/_runtime.py; do not edit here, edit it there.
"""Run-time support of the generated converters: the loss report, float32/float16 emulation,
C integer conversions as a Cortex-M performs them, and the few array algorithms the mappings
name (MAVLink cell packing, the Linux OCV table lookup).

Standard library only: this file is copied verbatim into ``generated/convert/_runtime.py``.
"""

from __future__ import annotations

import math
import struct
from array import array
from collections.abc import Iterator, Sequence
from typing import Any


class ConversionError(ValueError):
    """A conversion that cannot be made (a policy with no behaviour for the pair, bad input)."""


class LossEntry:
    """One thing that did not survive a conversion: ``kind`` is ``unknown`` (a target field left
    at its invalid value), ``dropped`` (source information with no place in the target),
    ``clamped`` (a value forced into range) or ``rounded`` (a value quantised)."""

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

    __slots__ = ("_keys",)

    def __init__(self) -> None:
        self._keys: dict[tuple[str, str, str], None] = {}

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

    def discard(self, kind: str, field: str) -> None:
        """Withdraw entries (a later rule filled a field an earlier one left unknown)."""
        self._keys = {k: None for k in self._keys if not (k[0] == kind and k[1] == field)}

    def fields(self, kind: str) -> list[str]:
        return [k[1] for k in self._keys if k[0] == kind]

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


def f32(x: float) -> float:
    """``x`` rounded to IEEE float32, as a C ``float`` holds it (overflow becomes infinity)."""
    try:
        result: float = _F32.unpack(_F32.pack(x))[0]
    except OverflowError:
        return math.copysign(math.inf, x)
    return result


def f16(x: float, rep: LossReport | None, label: str) -> float:
    """``x`` as a saturated IEEE float16 holds it (DroneCAN ``float16``): finite values beyond
    the range clamp to +-65504, the rest round to nearest even."""
    if math.isnan(x) or math.isinf(x):
        return x
    if abs(x) > F16_MAX:
        if rep is not None:
            rep.clamped(label, f"{x!r} beyond float16")
        return math.copysign(F16_MAX, x)
    y: float = _F16.unpack(_F16.pack(x))[0]
    if rep is not None and y != x:
        rep.rounded(label, "float16")
    return y


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
    if math.isinf(x):
        n = hi if x > 0 else lo
    else:
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


def bytes_out(text: str, capacity: int | None, rep: LossReport | None, label: str) -> bytes:
    data = text.encode("utf-8")
    if capacity is not None and len(data) > capacity:
        if rep is not None:
            rep.clamped(label, f"{len(data)} bytes, room for {capacity}")
        data = data[:capacity]
    return data


# -- arrays ---------------------------------------------------------------------------------


def leading(values: Sequence[float], marker: float | None) -> list[float]:
    """The values before the first ``marker`` (all of them when there is none)."""
    out: list[float] = []
    for v in values:
        if marker is not None and is_marker(v, marker):
            break
        out.append(v)
    return out


def dt_first(value: Any) -> Any:
    """The first scalar of a devicetree property (``<3200000>`` is ``[[3200000]]``), or None."""
    while isinstance(value, list | tuple):
        if not value:
            return None
        value = value[0]
    return value


def mavlink_cells_in(
    main: Sequence[int], ext: Sequence[int], main_marker: int, ext_marker: int, spill: int
) -> tuple[list[int] | None, int | None]:
    """(cells, pack) from BATTERY_STATUS voltages: cells up to the first marker, the extension
    cells only when all main cells are used; a lone value or a spill (``spill`` in the first
    cell) is the pack voltage with cells unknown."""
    cells = leading(main, main_marker)
    if len(cells) == len(main):
        cells += leading(ext, ext_marker)
    if not cells:
        return None, None
    ints = [int(c) for c in cells]
    if len(ints) == 1 or ints[0] == spill:
        return None, sum(ints)
    return ints, sum(ints)


def mavlink_cells_out(
    cells: Sequence[float] | None,
    pack: float | None,
    n_main: int,
    n_ext: int,
    main_marker: int,
    ext_marker: int,
    rep: LossReport | None,
    label_main: str,
    label_ext: str,
) -> tuple[list[int], list[int]]:
    """BATTERY_STATUS voltages from cells (in mV), else from the pack voltage (mV) spilled in
    ``main_marker - 1`` chunks; a measured 0 in the extension cells is sent as 1."""
    main = [main_marker] * n_main
    ext = [ext_marker] * n_ext
    top = main_marker - 1
    if cells:
        if len(cells) > n_main + n_ext:
            if rep is not None:
                rep.clamped(label_ext, f"{len(cells)} cells, room for {n_main} + {n_ext}")
            cells = cells[: n_main + n_ext]
        for i, c in enumerate(cells):
            if i < n_main:
                main[i] = to_int(c, 0, top, rep, label_main)
            else:
                ext[i - n_main] = max(to_int(c, 0, top, rep, label_ext), 1 if ext_marker == 0 else 0)
        return main, ext
    if pack is not None and not math.isnan(pack):
        mv = to_int(pack, 0, top * n_main, rep, label_main)
        i = 0
        while mv > top and i < n_main - 1:
            main[i] = top
            mv -= top
            i += 1
        main[i] = mv
    elif rep is not None:
        rep.unknown(label_main)
    return main, ext


def px4_stream_cells(
    voltage_v: float,
    cells: Sequence[float],
    cell_count: int,
    connected: bool,
    mul: float,
    threshold: float,
    n_main: int,
    n_ext: int,
    main_fill: int,
    ext_fill: int,
    rep: LossReport | None,
    label: str,
) -> tuple[list[int], list[int]]:
    """PX4's BATTERY_STATUS cell fill (see the mapping's doc), float32 throughout."""
    main = [main_fill] * n_main
    ext = [ext_fill] * n_ext
    if not connected:
        return main, ext
    chunk = main_fill - 1
    if cell_count == 0 or f32(cells[0]) < threshold:
        total = f32(f32(voltage_v) * mul)
        fields = c_div(c_float_to_int(total, 32, True), chunk) + 1
        if 1 <= fields <= n_main:
            rest = total
            for i in range(fields - 1):
                main[i] = chunk
                rest = f32(rest - chunk)
            main[fields - 1] = c_float_to_int(rest, 16, False, rep, label)
        elif rep is not None:
            rep.clamped(label, f"pack voltage needs {fields} fields")
        return main, ext
    slots = min(cell_count, len(cells), n_main + n_ext)
    for i in range(slots):
        v = c_float_to_int(f32(f32(cells[i]) * mul), 16, False, rep, label)
        if i < n_main:
            main[i] = v
        else:
            ext[i - n_main] = v
    return main, ext


def px4_receiver_cells(
    voltages: Sequence[int], n_cells: int, marker: int, div: float
) -> tuple[list[float], int, float]:
    """PX4's receiver: cells while below ``marker`` (at most len(voltages)), v / div in float32, summed."""
    n = 0
    limit = min(len(voltages), n_cells)
    while n < limit and voltages[n] < marker:
        n += 1
    # float32 rounding of every quotient at once (an array('f') store is the C cast f32 makes)
    cells = array("f", [float(v) / div for v in voltages[:n]]).tolist() + [0.0] * (n_cells - n)
    acc = array("f", b"\0\0\0\0")
    for c in cells[:n]:
        acc[0] = acc[0] + c  # the running sum is rounded at each step, as in C
    return cells, n, acc[0]


# -- devicetree -----------------------------------------------------------------------------


def cells_from_design(
    vmax: float | None, vmin: float | None, chemistry: str | None, charged: dict[str, float], empty: dict[str, float]
) -> int | None:
    """Cells in series from a design voltage and the chemistry's cell voltage (nearest whole)."""
    if chemistry is None:
        return None
    for volts, table in ((vmax, charged), (vmin, empty)):
        per_cell = table.get(chemistry)
        if volts is not None and per_cell:
            n = math.floor(volts / per_cell + 0.5)
            if n >= 1:
                return n
    return None


def _s32(value: int) -> int:
    """Wrap to a C int, as the kernel's arithmetic does."""
    value &= 0xFFFFFFFF
    return value - (1 << 32) if value & 0x80000000 else value


def ocv_to_capacity(
    tables: Sequence[Sequence[Sequence[int]]], temps_celsius: Sequence[int], ocv_uv: int, temp_celsius: int
) -> int:
    """Capacity percent for an open-circuit voltage, as the Linux power-supply core computes it:
    the table of the nearest temperature (first on a tie, at most 20 looked at), then C ``int``
    linear interpolation between the points around ``ocv_uv`` (tables run from high to low
    voltage), clamped at the ends."""
    best, best_diff = 0, (1 << 31) - 1
    for i, t in enumerate(temps_celsius[: min(len(tables), 20)]):
        diff = _s32(abs(_s32(t - temp_celsius)))
        if diff < best_diff:
            best, best_diff = i, diff
    table = tables[best]
    i = 0
    while i < len(table) and not ocv_uv > table[i][0]:
        i += 1
    if i == 0:
        high = low = 0
    elif i == len(table):
        high = low = i - 1
    else:
        low, high = i, i - 1
    x0, y0 = table[low][0], table[low][1]
    x1, y1 = table[high][0], table[high][1]
    if y0 == y1 or ocv_uv == x0:
        return y0
    if x1 == x0 or ocv_uv == x1:
        return y1
    return _s32(y0 + c_div(_s32(_s32(y1 - y0) * _s32(ocv_uv - x0)), _s32(x1 - x0)))

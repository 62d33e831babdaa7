"""Source snippets for single DroneCAN values: saturation and truncation on encode, sign and
float views on decode, the v0 byte order of a field wider than 8 bits; plus a line collector."""

from __future__ import annotations

import keyword
import re

from .....ir import CastMode, FieldType, PrimitiveKind, PrimitiveType
from ...literals import hex_literal, py_literal, unparenthesized
from .plan import reorder_terms

F32_MAX = "_dc.F32_MAX"


# names a generated method uses itself, or that shadowing would break (the builtins its code calls)
_RESERVED = frozenset(
    {"acc", "tao", "head", "v", "rem", "n", "data", "cls", "self", "obj", "extra", "u", "t", "out", "_dc", "_struct"}
    | {"f32"}
    | {"bytes", "len", "str", "list", "int", "divmod", "range", "float", "bool", "any", "all", "sum", "min", "max"}
)
_NUMBERED = re.compile(r"[a-z][0-9]+")


class Lines:
    def __init__(self) -> None:
        self.out: list[str] = []
        self.level = 0
        self.count = 0
        self.used: set[str] = set()
        self.fields: dict[int, str] = {}  # field index -> the variable a decoder reads it into

    def add(self, line: str) -> None:
        self.out.append("    " * self.level + line)

    def fresh(self, stem: str) -> str:
        """A numbered temporary (``k3``): for the loop counters and lengths no field names."""
        self.count += 1
        name = f"{stem}{self.count}"
        self.used.add(name)
        return name

    def field_var(self, index: int, label: str) -> str:
        """The one variable of this method holding field ``index`` (named for it on first use)."""
        if index not in self.fields:
            self.fields[index] = self.named(label)
        return self.fields[index]

    def named(self, label: str, suffix: str = "") -> str:
        """A temporary named for the field it holds, so the code reads against the layout comment:
        ``BatteryInfo.cells[2].voltage`` with suffix ``f16`` gives ``cells_2_voltage_f16``; a name
        already used, reserved, or shaped like a numbered temporary gets a trailing underscore."""
        field = label.split(".", 1)[1] if "." in label else label
        name = re.sub(r"\W+", "_", field).strip("_").lower() or "value"
        if suffix:
            name += "_" + suffix
        if name[0].isdigit():
            name = "f_" + name
        while name in self.used or name in _RESERVED or _NUMBERED.fullmatch(name) or keyword.iskeyword(name):
            name += "_"
        self.used.add(name)
        return name

    def text(self, indent: int) -> str:
        pad = "    " * indent
        return "\n".join(pad + line if line else "" for line in self.out)


def error(kind: str, prefix: str, value: str = "", suffix: str = "") -> str:
    """Source building ``_dc.<kind>`` with a message: schema text only through literals."""
    parts = [py_literal(prefix)] + ([value] if value else []) + ([py_literal(suffix)] if suffix else [])
    return f"_dc.{kind}({' + '.join(parts)})"


def mask(bits: int) -> str:
    """The literal of ``bits`` one bits; past 64 bits, as a shift (a hex literal would outgrow a line)."""
    return hex_literal((1 << bits) - 1) if bits <= 64 else f"((1 << {bits}) - 1)"


def stream(expr: str, width: int) -> str:
    """Stream bits (MSB-first order) of a ``width``-bit unsigned value held in a simple name."""
    if width <= 8:
        return expr
    parts = []
    for vshift, mask, sshift in reorder_terms(width):
        term = f"(({expr} >> {vshift}) & {hex_literal(mask)})" if vshift else f"({expr} & {hex_literal(mask)})"
        parts.append(f"({term} << {sshift})" if sshift else term)
    return "(" + " | ".join(parts) + ")"


def unstream(expr: str, width: int) -> str:
    """Inverse of :func:`_stream`: the value of stream bits held in a simple name."""
    if width <= 8:
        return expr
    parts = []
    for vshift, mask, sshift in reorder_terms(width):
        term = f"(({expr} >> {sshift}) & {hex_literal(mask)})" if sshift else f"({expr} & {hex_literal(mask)})"
        parts.append(f"({term} << {vshift})" if vshift else term)
    return "(" + " | ".join(parts) + ")"


def clamp(r: str, lo: str, hi: str, below: str | None = None, above: str | None = None) -> str:
    below = lo if below is None else below
    above = hi if above is None else above
    return f"({r} if {lo} <= {r} <= {hi} else ({above} if {r} > {hi} else ({below} if {r} < {lo} else {r})))"


def saturate(r: str, lo: str, hi: str) -> str:
    """A saturated float: finite values beyond the range clamp to it; infinity and NaN pass unchanged
    (DSDL v0: "infinity will be preserved"; libuavcan's FloatSpec::saturate skips non-finite values)."""
    inner = f"({lo} if -_dc.INF < {r} < {lo} else {r})"
    return f"({r} if {lo} <= {r} <= {hi} else ({hi} if {hi} < {r} < _dc.INF else {inner}))"


def encode_value(t: PrimitiveType, raw: str, *, pattern: bool) -> str:
    """What the encoder hands struct (``pattern``: the unsigned bit pattern) for value ``raw``.

    ``raw`` must be a simple name when the result uses it more than once."""
    kind, bits, sat = t.kind, t.bits, t.cast is CastMode.SATURATED
    if kind is PrimitiveKind.BOOL:
        return f"(1 if {raw} else 0)"
    if kind is PrimitiveKind.UINT:
        if not sat:
            return f"({raw} & {mask(bits)})"
        hi = str((1 << bits) - 1)
        return f"({raw} if 0 <= {raw} <= {hi} else ({hi} if {raw} > {hi} else 0))"
    if kind is PrimitiveKind.INT:
        if not sat:
            return f"({raw} & {mask(bits)})"
        lo, hi = str(-(1 << (bits - 1))), str((1 << (bits - 1)) - 1)
        value = f"({raw} if {lo} <= {raw} <= {hi} else ({hi} if {raw} > {hi} else {lo}))"
        return f"({value} & {mask(bits)})" if pattern else value
    if kind is PrimitiveKind.FLOAT:
        if bits == 16:
            return f"_dc.f16s({raw})" if sat else f"_dc.f16t({raw})"
        if bits == 64:  # a Python float is a float64: nothing is out of range, infinity is kept in both modes
            value = raw
        elif sat:
            value = saturate(raw, f"-{F32_MAX}", F32_MAX)
        else:
            value = clamp(raw, f"-{F32_MAX}", F32_MAX, "-_dc.INF", "_dc.INF")
        if pattern:
            inner = unparenthesized(value)
            return f"_dc.f32bits({inner})" if bits == 32 else f"_dc.f64bits({inner})"
        return value
    raise ValueError(f"cannot encode {t.name}")


def needs_name(t: PrimitiveType) -> bool:
    """Whether :func:`encode_value` uses its input more than once."""
    if t.kind is PrimitiveKind.INT or t.kind is PrimitiveKind.UINT:
        return t.cast is CastMode.SATURATED
    return t.kind is PrimitiveKind.FLOAT and t.bits == 32


def decode_pattern(t: PrimitiveType, b: str) -> str:
    """The field value of unsigned bit pattern ``b`` (a simple name or parenthesised)."""
    kind, bits = t.kind, t.bits
    if kind is PrimitiveKind.BOOL:
        return f"({b} != 0)"
    if kind is PrimitiveKind.UINT:
        return b
    if kind is PrimitiveKind.INT:
        sign = hex_literal(1 << (bits - 1))
        return f"(({b} ^ {sign}) - {sign})"
    if kind is PrimitiveKind.FLOAT:
        return {16: "_dc.f16v", 32: "_dc.f32v", 64: "_dc.f64v"}[bits] + f"({unparenthesized(b)})"
    raise ValueError(f"cannot decode {t.name}")


def structable_element(t: FieldType) -> PrimitiveType | None:
    """A primitive array element struct can pack whole (a word-sized integer or float)."""
    if not isinstance(t, PrimitiveType) or t.bits % 8 or t.bits not in (8, 16, 32, 64):
        return None
    if t.kind in (PrimitiveKind.UINT, PrimitiveKind.INT, PrimitiveKind.FLOAT) and not (
        t.kind is PrimitiveKind.FLOAT and t.bits == 8
    ):
        return t
    return None

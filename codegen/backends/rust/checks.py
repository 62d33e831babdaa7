"""The validators: per field a check of one value, the rules in the order the Python validators
apply them (sentinel, NaN, type bounds, range, enum, bitmask) and the first broken one reported, so
the Rust crate and the Python package report the same problems for the same message."""

from __future__ import annotations

from dataclasses import dataclass

from ...ir import ArrayType, EnumKind, Field, PrimitiveKind, PrimitiveType, Schema, StringType, type_bounds
from .types import equals, f64_bound, is_exact_width, scalar


@dataclass(frozen=True)
class FieldCheck:
    """The check of one field: ``fn_name(v) -> Option<Rule>`` over each value it holds."""

    field: str  # the schema's name, as problems report it
    ident: str
    fn_name: str
    rust: str  # the value's Rust type
    body: list[str]  # statements of the check function
    count: int | None  # None: a scalar; else the array's capacity
    dynamic: bool
    first: tuple[PrimitiveType, int | float] | None  # MAVLink [X:]: element 0 at this value makes the array unknown


def _ranges(values: list[int]) -> str:
    """``0 | 1 | 2 | 5`` as ``0..=2 | 5`` (clippy asks for ranges over runs)."""
    runs: list[tuple[int, int]] = []
    for v in sorted(set(values)):
        if runs and v == runs[-1][1] + 1:
            runs[-1] = (runs[-1][0], v)
        else:
            runs.append((v, v))
    return " | ".join(str(a) if a == b else f"{a}..={b}" for a, b in runs)


def _enum_facts(schema: Schema, f: Field) -> tuple[list[int] | None, int | None]:
    """(allowed values of value enums, mask of bitmask enums); members named RESERVED stay unset."""
    values: list[int] = []
    mask: int | None = None
    for name in f.enums:
        e = schema.enum(name)
        for entry in e.entries:
            if e.kind is EnumKind.VALUE:
                values.append(entry.value)
                continue
            bit = entry.value if e.kind is EnumKind.BITMASK else 1 << entry.value
            if "RESERVED" not in entry.name.upper():
                mask = (mask or 0) | bit
        if e.kind is not EnumKind.VALUE and mask is None:
            mask = 0
    if mask is not None:
        return None, mask
    return (values or None), None


def _as_f64(rust: str) -> str:
    return "v as f64" if rust in ("u64", "i64") else "f64::from(v)"


def _body(schema: Schema, f: Field, t: PrimitiveType) -> list[str]:
    rust = scalar(t)
    out: list[str] = []
    s = f.invalid
    is_float = t.kind is PrimitiveKind.FLOAT
    if s is not None:
        out.append(f"if {equals(t, s.value, 'v')} {{ return None; }}")
    checks: list[str] = []  # (condition, rule) statements after the sentinel
    if is_float and not (s is not None and s.is_nan):
        checks.append("if v.is_nan() { return Some(Rule::Nan); }")
    low, high = type_bounds(t, f.range)
    x = _as_f64(rust)
    type_low, type_high = type_bounds(t, None)
    inf = float("inf")
    if is_float and t.bits >= 32:
        # the Rust type holds exactly the width's finite values, so beyond them is only an infinity
        if low != -inf and high != inf:
            checks.append("if v.is_infinite() { return Some(Rule::TypeBounds); }")
        elif low != -inf:
            checks.append(f"if v == {rust}::NEG_INFINITY {{ return Some(Rule::TypeBounds); }}")
        elif high != inf:
            checks.append(f"if v == {rust}::INFINITY {{ return Some(Rule::TypeBounds); }}")
    elif is_float:  # float16 held in an f32
        checks.append(f"if {x} < {f64_bound(low)} {{ return Some(Rule::TypeBounds); }}")
        checks.append(f"if {x} > {f64_bound(high)} {{ return Some(Rule::TypeBounds); }}")
    elif not is_exact_width(t):  # a DSDL odd width held in the next Rust integer
        if t.kind is PrimitiveKind.INT:
            checks.append(f"if v < {int(low)} {{ return Some(Rule::TypeBounds); }}")
        checks.append(f"if v > {int(high)} {{ return Some(Rule::TypeBounds); }}")
    r = f.range
    if r is not None and t.kind is not PrimitiveKind.BOOL:
        for bound, op, strict in ((r.minimum, "<", r.exclusive_minimum), (r.maximum, ">", r.exclusive_maximum)):
            if bound is None or abs(bound) == float("inf"):
                continue
            edge = type_low if op == "<" else type_high
            implied = bound < type_low if op == "<" else bound > type_high
            if not is_float and (implied or (bound == edge and not strict)):
                continue  # the type already holds it (clippy refuses an absurd comparison)
            cmp = op + ("=" if strict else "")
            if not is_float and float(bound).is_integer():
                checks.append(f"if v {cmp} {int(bound)} {{ return Some(Rule::Range); }}")
            else:
                checks.append(f"if {x} {cmp} {f64_bound(bound)} {{ return Some(Rule::Range); }}")
    values, mask = _enum_facts(schema, f)
    if not is_float and t.kind is not PrimitiveKind.BOOL:
        if values is not None:
            fit = [v for v in values if type_low <= v <= type_high]
            checks.append(f"if !matches!(v, {_ranges(fit)}) {{ return Some(Rule::Enum); }}")
        elif mask is not None and mask & ((1 << t.bits) - 1) != (1 << t.bits) - 1:  # else every value passes
            width = int(rust[1:])
            bits = "v" if rust[0] == "u" else f"(v as u{width})"  # a signed field's bits as they are sent
            checks.append(f"if {bits} & !{mask & ((1 << width) - 1):#x} != 0 {{ return Some(Rule::Bitmask); }}")
    if not checks:
        return []
    return [*out, *checks, "None"]


def field_check(schema: Schema, f: Field, ident: str) -> FieldCheck | None:
    """The check of field ``f`` (None when its Rust type already says everything)."""
    t = f.type
    count: int | None = None
    dynamic = False
    if isinstance(t, ArrayType):
        if not isinstance(t.element, PrimitiveType):
            return None
        count, dynamic, t = t.capacity or 1, t.dynamic, t.element
    if isinstance(t, StringType) or not isinstance(t, PrimitiveType):
        return None
    if t.kind in (PrimitiveKind.CHAR, PrimitiveKind.VOID, PrimitiveKind.BOOL):
        return None
    body = _body(schema, f, t)
    if not body:
        return None
    first = None
    if count is not None and f.invalid is not None and f.invalid.first_decides:
        first = (t, f.invalid.value)
    return FieldCheck(f.name, ident, f"check_{ident.strip('_')}", scalar(t), body, count, dynamic, first)

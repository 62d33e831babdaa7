"""The validators as C: per field a check of one value, the rules in the order the Python validators
apply them (sentinel, NaN, type bounds, range, enum, bitmask) and the first broken one reported, so
the C library and the Python package report the same problems for the same message. Comparisons
the field's type already decides are left out (gcc's -Wextra refuses them)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ...ir import (
    ArrayType,
    CompositeType,
    EnumKind,
    Field,
    Message,
    PrimitiveKind,
    PrimitiveType,
    Schema,
    StringType,
    type_bounds,
)
from .types import ident, scalar, type_name


@dataclass(frozen=True)
class FieldCheck:
    """``battgen_rule fn_name(ctype v)``: the rule one value breaks, BATTGEN_RULE_NONE if none."""

    fn_name: str
    ctype: str
    body: list[str]
    count: int | None  # None: a scalar; else the array's capacity
    dynamic: bool
    first: str | None  # MAVLink [X:]: the condition on `v` (element 0) that makes the array unknown


@dataclass(frozen=True)
class CheckUse:
    """One check as a validator runs it, on a field of the message or of one nested in it."""

    path: str  # as problems name it (``timestamp.usec``)
    target: str  # the value's expression (``m->timestamp.usec``)
    check: FieldCheck


def _is_exact_width(t: PrimitiveType) -> bool:
    return t.kind not in (PrimitiveKind.UINT, PrimitiveKind.INT) or t.bits in (8, 16, 32, 64)


def _c_bits(t: PrimitiveType) -> int:
    return next(w for w in (8, 16, 32, 64) if t.bits <= w)


def _int_literal(v: int, ctype: str) -> str:
    suffix = "ULL" if ctype == "uint64_t" else "LL" if ctype == "int64_t" else "u" if ctype.startswith("u") else ""
    if v < 0:
        return f"({v + 1}{suffix} - 1)" if v == -(2**63) else f"{v}{suffix}"
    return f"{v}{suffix}"


def _double(value: float) -> str:
    text = repr(float(value))
    return text if ("." in text or "e" in text) else text + ".0"


def _float_fn(t: PrimitiveType, what: str, expr: str) -> str:
    """``battgen_f32_is_nan(expr)`` and the like (float16 is held in a float)."""
    return f"battgen_f{64 if t.bits > 32 else 32}_is_{what}({expr})"


def _equals(t: PrimitiveType, value: int | float, expr: str) -> str:
    if isinstance(value, float) and math.isnan(value):
        return _float_fn(t, "nan", expr)
    if t.kind is PrimitiveKind.FLOAT:
        return f"{expr} == {_double(float(value))}"
    return f"{expr} == {_int_literal(int(value), scalar(t))}"


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


def _allowed(values: list[int], low: float, high: float, ctype: str) -> str:
    """``v`` is one of ``values`` (runs as ranges; a comparison the type decides left out)."""
    runs: list[tuple[int, int]] = []
    for v in sorted(set(values)):
        if runs and v == runs[-1][1] + 1:
            runs[-1] = (runs[-1][0], v)
        else:
            runs.append((v, v))
    terms = []
    for a, b in runs:
        if a == b:
            terms.append(f"v == {_int_literal(a, ctype)}")
            continue
        part = [f"v >= {_int_literal(a, ctype)}"] if a > low else []
        part += [f"v <= {_int_literal(b, ctype)}"] if b < high else []
        terms.append(("(" + " && ".join(part) + ")" if len(part) > 1 else part[0]) if part else "1")
    return " || ".join(terms) if terms else "0"


def _body(schema: Schema, f: Field, t: PrimitiveType) -> list[str]:
    ctype = scalar(t)
    s = f.invalid
    is_float = t.kind is PrimitiveKind.FLOAT
    out = [f"if ({_equals(t, s.value, 'v')}) {{ return BATTGEN_RULE_NONE; }}"] if s is not None else []
    checks: list[str] = []

    def rule(cond: str, name: str) -> None:
        checks.append(f"if ({cond}) {{ return BATTGEN_RULE_{name}; }}")

    if is_float and not (s is not None and s.is_nan):
        rule(_float_fn(t, "nan", "v"), "NAN")
    low, high = type_bounds(t, f.range)
    type_low, type_high = type_bounds(t, None)
    inf = float("inf")
    x = "(double)v"
    if is_float and t.bits >= 32:
        # the C type holds exactly the width's finite values, so beyond them is only an infinity
        if low != -inf and high != inf:
            rule(_float_fn(t, "inf", "v"), "TYPE_BOUNDS")
        elif low != -inf:
            rule(f"{_float_fn(t, 'inf', 'v')} && v < 0", "TYPE_BOUNDS")
        elif high != inf:
            rule(f"{_float_fn(t, 'inf', 'v')} && v > 0", "TYPE_BOUNDS")
    elif is_float:  # float16 held in a float
        rule(f"{x} < {_double(low)}", "TYPE_BOUNDS")
        rule(f"{x} > {_double(high)}", "TYPE_BOUNDS")
    elif not _is_exact_width(t):  # a DSDL odd width held in the next C integer
        if t.kind is PrimitiveKind.INT:
            rule(f"v < {_int_literal(int(low), ctype)}", "TYPE_BOUNDS")
        rule(f"v > {_int_literal(int(high), ctype)}", "TYPE_BOUNDS")
    r = f.range
    if r is not None and t.kind is not PrimitiveKind.BOOL:
        c_low, c_high = type_low, type_high
        if not is_float:  # what the C integer holds, wider than a DSDL odd width
            c_low, c_high = type_bounds(PrimitiveType(t.kind, _c_bits(t)), None)
        for bound, op, strict in ((r.minimum, "<", r.exclusive_minimum), (r.maximum, ">", r.exclusive_maximum)):
            if bound is None or abs(bound) == inf:
                continue
            edge = c_low if op == "<" else c_high
            implied = bound < c_low if op == "<" else bound > c_high
            if not is_float and (implied or (bound == edge and not strict)):
                continue  # the type already holds it
            cmp = op + ("=" if strict else "")
            if not is_float and float(bound).is_integer():
                rule(f"v {cmp} {_int_literal(int(bound), ctype)}", "RANGE")
            else:
                rule(f"{x} {cmp} {_double(bound)}", "RANGE")
    values, mask = _enum_facts(schema, f)
    if not is_float and t.kind is not PrimitiveKind.BOOL:
        c_low, c_high = type_bounds(PrimitiveType(t.kind, _c_bits(t)), None)
        if values is not None:
            fit = [v for v in values if type_low <= v <= type_high]
            allowed = _allowed(fit, c_low, c_high, ctype)
            rule(f"!({allowed})" if " " in allowed and not allowed.startswith("(") else f"!{allowed}", "ENUM")
        elif mask is not None and mask & ((1 << t.bits) - 1) != (1 << t.bits) - 1:  # else every value passes
            w = _c_bits(t)
            bits = "v" if ctype.startswith("u") else f"(uint{w}_t)v"  # a signed field's bits as sent
            unset = ~mask & ((1 << w) - 1)
            suffix = "ULL" if w == 64 else "u"
            rule(f"({bits} & {unset:#x}{suffix}) != 0u", "BITMASK")
    if not checks:
        return []
    return [*out, *checks, "return BATTGEN_RULE_NONE;"]


def field_check(schema: Schema, msg: Message, f: Field) -> FieldCheck | None:
    """The check of field ``f`` (None when its C type already says everything)."""
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
        first = _equals(t, f.invalid.value, "{}")
    return FieldCheck(f"check_{type_name(msg.qualified_name)}_{ident(f.name)}", scalar(t), body, count, dynamic, first)


def checks_of(schema: Schema, msg: Message) -> list[FieldCheck]:
    """The check functions a message's fields need, in field order."""
    return [c for f in msg.fields if not f.is_padding and (c := field_check(schema, msg, f)) is not None]


def check_uses(schema: Schema, msg: Message, path: str = "", target: str = "m->", depth: int = 0) -> list[CheckUse]:
    """Every check of ``msg``'s fields and, path by path, of the messages nested in it (not in arrays)."""
    out: list[CheckUse] = []
    for f in msg.fields:
        if f.is_padding:
            continue
        c = field_check(schema, msg, f)
        if c is not None:
            out.append(CheckUse(path + f.name, target + ident(f.name), c))
        elif isinstance(f.type, CompositeType) and depth < 8:
            inner = schema.message(f.type.name)
            out += check_uses(schema, inner, f"{path}{f.name}.", f"{target}{ident(f.name)}.", depth + 1)
    return out


def validator(uses: list[CheckUse]) -> list[str]:
    """The statements of a message's validator over `m`, `out`, `cap` and the count `n`."""
    lines: list[str] = []
    for u in uses:
        c = u.check
        if c.count is None:
            lines += [
                f"r = {c.fn_name}({u.target});",
                f'if (r != BATTGEN_RULE_NONE) {{ battgen_report(out, cap, &n, "{u.path}", -1, r); }}',
            ]
            continue
        end = f"{c.count}u"
        if c.dynamic:
            lines.append(
                f'if ({u.target}_len > {c.count}u) {{ battgen_report(out, cap, &n, "{u.path}", -1, '
                "BATTGEN_RULE_LENGTH); }"
            )
            end = f"({u.target}_len < {c.count}u ? {u.target}_len : {c.count}u)"
        loop = [
            f"for (i = 0; i < {end}; i++) {{",
            f"r = {c.fn_name}({u.target}[i]);",
            f'if (r != BATTGEN_RULE_NONE) {{ battgen_report(out, cap, &n, "{u.path}", (int32_t)i, r); }}',
            "}",
        ]
        if c.first is not None:
            loop = [f"if (!({c.first.format(u.target + '[0]')})) {{", *loop, "}"]
        lines += loop
    return lines

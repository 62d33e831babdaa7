"""Per-field checks of the generated validators: a fast-path condition specialised to the field
(true when the value may be wrong) and the spec the runtime's careful ``diag`` reads once it is.

The fast path must never pass a value ``diag`` would report; it may flag a value ``diag`` then
finds fine (an int 1 in a bool field). Bounds fold the type's width, the schema range and the
sentinel into one chained comparison or one bit test wherever possible.
"""

from __future__ import annotations

from dataclasses import replace

from ....ir import (
    ArrayType,
    CompositeType,
    Field,
    FieldType,
    PrimitiveKind,
    PrimitiveType,
    Schema,
    Sentinel,
    StringType,
    type_bounds,
)
from ..literals import hex_literal, py_literal, text_literal, unparenthesized
from .bounds import EnumFacts, enum_facts, folded, inside, number

V = "\x00V\x00"  # placeholder for the value expression in a condition


class NumberCheck:
    def __init__(
        self, t: PrimitiveType, f: Field, sentinel: Sentinel | None, facts: EnumFacts | None, label: str = ""
    ) -> None:
        self.t = t
        self.f = f
        self.sentinel = sentinel
        self.facts = facts
        self.label = label  # the column's doc, named in messages
        self.bounds = folded(t, f.range) if t.kind not in (PrimitiveKind.CHAR, PrimitiveKind.VOID) else None

    def spec(self) -> str:
        t, f = self.t, self.f
        args = [f"type={py_literal(t.name)}", f"kind={py_literal(t.kind.value)}"]
        if self.label:
            args.append(f"label={text_literal(self.label)}")
        if t.kind is PrimitiveKind.CHAR:
            args += ["low=0", "high=255"]
        else:
            low, high = type_bounds(t, f.range)
            args += [f"low={number(low, t)}", f"high={number(high, t)}"]
        unit = f.unit.symbol if f.unit is not None else (f.unit_text or "")
        if unit and unit != "1":  # a dimensionless value ('[-]') reads as a bare number
            args.append(f"unit={py_literal(unit)}")
        if f.range is not None:
            r = f.range
            if r.minimum is not None:
                args.append(f"minimum={py_literal(r.minimum)}")
            if r.maximum is not None:
                args.append(f"maximum={py_literal(r.maximum)}")
            if r.exclusive_minimum:
                args.append("exclusive_minimum=True")
            if r.exclusive_maximum:
                args.append("exclusive_maximum=True")
        if self.sentinel is not None:
            args.append(f"sentinel={number(self.sentinel.value, t)}")
            args.append(f"sentinel_text={py_literal(self.sentinel.text)}")
        facts = self.facts
        if facts is not None and facts.values is not None:
            items = ", ".join(f"{v}: {py_literal(n)}" for v, n in sorted(facts.values.items()))
            args.append("values={" + items + "}")
        if facts is not None and facts.mask is not None:
            args.append(f"mask={hex_literal(facts.mask)}")
            items = ", ".join(f"{hex_literal(b)}: {py_literal(n)}" for b, n in sorted(facts.bits.items()))
            args.append("bits={" + items + "}")
        return "_v.Number(" + ", ".join(args) + ")"

    def bad(self) -> str:
        """Condition on :data:`V` that is true when the value may break a rule."""
        t, s = self.t, self.sentinel
        if t.kind is PrimitiveKind.BOOL:
            return f"({V} is not True and {V} is not False)"
        if t.kind is PrimitiveKind.CHAR:
            return f"({V}.__class__ is not str or len({V}) > 1)"
        b = self.bounds
        assert b is not None
        facts = self.facts
        if t.kind is PrimitiveKind.FLOAT:
            lo = "<" if b.low_strict else "<="
            hi = "<" if b.high_strict else "<="
            cond = f"not ({number(b.low, t)} {lo} {V} {hi} {number(b.high, t)})"  # false for NaN too
            if s is not None and s.is_nan:
                cond += f" and {V} == {V}"
            elif s is not None and not inside(b, float(s.value)):
                cond += f" and {V} != {number(s.value, t)}"
            return f"({cond})"
        # integers: a bit test rejects floats (TypeError) and values beyond the width at once
        tlow, thigh = type_bounds(t, None)
        parts: list[tuple[str, bool]] = []  # (condition, whether the sentinel may trip it)
        if facts is not None and facts.values is not None:
            allowed = {v for v in facts.values if tlow <= v <= thigh}
            if s is not None:
                allowed.add(int(s.value))
            parts.append((f"{V} not in {{" + ", ".join(str(v) for v in sorted(allowed)) + "}", False))
        elif facts is not None and facts.mask is not None:
            parts.append((f"{V} & {~facts.mask}", s is not None and int(s.value) & ~facts.mask != 0))
        elif tlow == 0:
            parts.append((f"{V} & {-(int(thigh) + 1)}", False))
        else:
            parts.append((f"({V} + {-int(tlow)}) & {2 * int(tlow)}", False))
        if (b.low, b.high, b.low_strict, b.high_strict) != (tlow, thigh, False, False):
            lo = "<" if b.low_strict else "<="
            hi = "<" if b.high_strict else "<="
            parts.append(
                (
                    f"not ({number(b.low, t)} {lo} {V} {hi} {number(b.high, t)})",
                    s is not None and not inside(b, float(s.value)),
                )
            )
        conds = [f"({c} and {V} != {int(s.value)})" if trips and s is not None else c for c, trips in parts]
        return "(" + " or ".join(conds) + ")"


class TextCheck:
    def __init__(self, t: StringType, f: Field, label: str = "") -> None:
        self.t = t
        self.f = f
        self.label = label

    def spec(self) -> str:
        args = [f"label={text_literal(self.label)}"] if self.label else []
        if self.t.capacity is not None:
            args.append(f"capacity={self.t.capacity}")
        strings = tuple(str(c) for c in self.f.choices)
        if strings:
            args.append(f"choices={py_literal(strings)}")
        if isinstance(self.f.const, str):
            args.append(f"const={py_literal(self.f.const)}")
        return "_v.Text(" + ", ".join(args) + ")"

    def bad(self) -> str:
        parts = []
        if isinstance(self.f.const, str):
            parts.append(f"{V} != {py_literal(self.f.const)}")
        elif self.f.choices:
            parts.append(f"{V} not in {{" + ", ".join(py_literal(str(c)) for c in self.f.choices) + "}")
        else:
            parts.append(f"{V}.__class__ is not str")
        if self.t.capacity is not None:
            parts.append(f"len({V}.encode()) > {self.t.capacity}")
        return "(" + " or ".join(parts) + ")"


class ArrayCheck:
    """An array; ``columns[i]`` (None where the column says nothing) checks element i instead of
    ``inner``. A column only narrows the element's checks, so the fast path tests every element
    against ``inner`` and, on top, each position whose column has a range against that column."""

    def __init__(
        self, t: ArrayType, inner: Check, depth: int, columns: list[Check | None], first: Sentinel | None = None
    ) -> None:
        self.t = t
        self.first = first  # MAVLink's [X:]: when element 0 is X the array is unknown, its elements unchecked
        self.inner = inner
        self.depth = depth
        self.columns = columns
        el = t.element
        self.byte = isinstance(el, PrimitiveType) and el.kind is PrimitiveKind.UINT and el.bits == 8
        self.ranged = [i for i, c in enumerate(t.columns) if c.range is not None and columns[i] is not None]

    def spec(self) -> str:
        t = self.t
        args = [self.inner.spec(), py_literal(t.capacity), py_literal(not t.dynamic)]
        if t.min_length:
            args.append(f"min_length={t.min_length}")
        if self.byte:
            args.append("byte=True")
        if any(c is not None for c in self.columns):
            specs = [c.spec() if c is not None else "None" for c in self.columns]
            args.append("columns=(" + ", ".join(specs) + ("," if len(specs) == 1 else "") + ")")
        if self.first is not None:
            assert isinstance(self.inner, NumberCheck)
            args.append(f"unknown_first={number(self.first.value, self.inner.t)}")
        return "_v.Array(" + ", ".join(args) + ")"

    def column_bad(self) -> list[str]:
        """Conditions on the positions whose column narrows the range; guarded by a length test
        unless the length checks before them already guarantee the position exists."""
        t, out = self.t, []
        for i in self.ranged:
            check = self.columns[i]
            assert check is not None
            cond = check.bad().replace(V, f"{V}[{i}]")
            sure = (t.capacity is not None and t.capacity > i) if not t.dynamic else t.min_length > i
            out.append(cond if sure else f"(len({V}) > {i} and {cond})")
        return out

    def length_bad(self) -> list[str]:
        t = self.t
        parts = []
        if not t.dynamic and t.capacity is not None:
            parts.append(f"len({V}) != {t.capacity}")
        else:
            if t.capacity is not None:
                parts.append(f"len({V}) > {t.capacity}")
            if t.min_length:
                parts.append(f"len({V}) < {t.min_length}")
        return parts

    def bad(self) -> str:
        parts = self.length_bad()
        if self.byte:
            parts.insert(0, f"{V}.__class__ is not bytes")
            elements = self.column_bad()
        else:
            item = f"_x{self.depth}"
            elements = [f"any({unparenthesized(self.inner.bad()).replace(V, item)} for {item} in {V})"]
            elements += self.column_bad()
        if self.first is not None and elements:
            s = self.first
            unknown = f"{V}[0] != {V}[0]" if s.is_nan else f"{V}[0] == {py_literal(s.value)}"
            elements = [f"(not (len({V}) > 0 and {unknown}) and ({' or '.join(elements)}))"]
        parts += elements
        return "(" + " or ".join(parts) + ")" if parts else "False"


class NestedCheck:
    def __init__(self, qualified: str) -> None:
        self.qualified = qualified

    def spec(self) -> str:
        return f"_v.Nested({py_literal(self.qualified)})"

    def bad(self) -> str:
        return f"({V}.QUALIFIED_NAME != {py_literal(self.qualified)} or bool({V}.validate()))"


Check = NumberCheck | TextCheck | ArrayCheck | NestedCheck


def build(schema: Schema, f: Field, t: FieldType, depth: int = 0, label: str = "") -> Check:
    if isinstance(t, PrimitiveType):
        return NumberCheck(t, f, f.invalid, enum_facts(schema, f), label)
    if isinstance(t, StringType):
        return TextCheck(t, f, label)
    if isinstance(t, CompositeType):
        return NestedCheck(t.name)
    columns: list[Check | None] = []
    for c in t.columns:
        if not c.doc and c.range is None and c.unit is None:
            columns.append(None)
            continue
        # the field as seen at this position: the column's range on top of the field's, its unit
        at = replace(f, range=c.range.intersect(f.range) if c.range is not None else f.range, unit=c.unit or f.unit)
        columns.append(build(schema, at, t.element, depth + 1, c.doc or label))
    first = f.invalid if depth == 0 and f.invalid is not None and f.invalid.first_decides else None
    inner = build(schema, f, t.element, depth + 1, label)
    return ArrayCheck(t, inner, depth, columns, first if isinstance(inner, NumberCheck) else None)

"""Rule emitters of the converter generator: each mapping rule becomes a few lines of plain Python.

A :class:`FunctionBuilder` renders one direction of one mapping as a function taking the source
endpoint's objects and returning the target's; each ``op`` has an emitter method. Every value a
schema supplies reaches the code through :func:`py_literal`, every name through :mod:`.naming`;
unit factors come from the IR's units (``Unit.factor_to``).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

from ....errors import BattgenError
from ....ir import (
    CONCEPTS_ENDPOINT,
    ArrayType,
    Concept,
    Endpoint,
    Field,
    FieldRef,
    Mapping,
    Message,
    Param,
    ParamValue,
    PrimitiveKind,
    PrimitiveType,
    Rule,
    Schema,
    StringType,
    Unit,
    units,
)
from .. import naming
from ..literals import py_literal

FLT_EPS = 1.1920928955078125e-07

# the temporaries emitters use; renamed per rule so each has one type
_TEMP = re.compile(r"\b_(?:v|w|c|p|x|n|m|b|e|f|s|a|l|t|ts|tb|tabs|cap|uv|hi|lo|ch|i)\b")

# ops whose rule still runs when an optional companion message it reads is absent
_HANDLES_MISSING = frozenset({"px4_bridge_cells"})


def _f32(x: float) -> float:
    import struct

    value: float = struct.unpack("<f", struct.pack("<f", x))[0]
    return value


def lit(value: object) -> str:
    return py_literal(value)


def num(value: float) -> str:
    """A float literal (``math.nan`` for NaN)."""
    return py_literal(float(value))


def params(rule: Rule) -> dict[str, ParamValue]:
    return {p.name: p.value for p in rule.params}


def pairs(value: ParamValue) -> list[tuple[str, ParamValue]]:
    """A mapping-valued param as (key, value) pairs in file order."""
    if not isinstance(value, tuple):
        return []
    return [(p.name, p.value) for p in value if isinstance(p, Param)]


def marker_value(value: ParamValue) -> float | int:
    """An ``unknown:`` entry: a number, or NaN / Infinity spelled as text."""
    if isinstance(value, bool):
        return int(value)
    if isinstance(value, int | float):
        return value
    if isinstance(value, str) and value.lower() in ("nan", "infinity", "-infinity", "inf", "-inf"):
        return float(value.lower().replace("infinity", "inf"))
    raise BattgenError(f"expected a number or NaN as an unknown marker, got {value!r}")


@dataclass
class Side:
    """One end of a function: the endpoint's messages (or the concepts) and their variables."""

    endpoint: Endpoint | None  # None: the concepts
    messages: list[Message]
    names: list[str]  # variable per message (or the single concept-state variable)

    def var(self, qualified: str) -> str:
        if self.endpoint is None:
            return self.names[0]
        return self.names[self.endpoint.messages.index(qualified)]

    def optional(self, qualified: str) -> bool:
        return self.endpoint is not None and self.endpoint.messages.index(qualified) > 0


@dataclass
class FunctionBuilder:
    schema: Schema
    mapping: Mapping
    concepts: dict[str, Concept]
    src: Side
    dst: Side
    name: str
    backward: bool
    classes: dict[str, str]  # qualified message name -> local class alias
    lines: list[str] = field(default_factory=list)
    module_consts: list[str] = field(default_factory=list)
    inputs: list[str] = field(default_factory=list)
    read: set[tuple[str, str]] = field(default_factory=set)
    written: set[tuple[str, str]] = field(default_factory=set)
    bit_masks: dict[tuple[str, str], int] = field(default_factory=dict)
    _counter: int = 0

    # -- names and facts -------------------------------------------------------------------

    def msg(self, qualified: str) -> Message:
        return self.schema.message(qualified)

    def fld(self, ref: FieldRef) -> Field:
        return self.msg(ref.message).field(ref.field)

    def attr(self, ref: FieldRef) -> str:
        if ref.message == CONCEPTS_ENDPOINT:
            return naming.identifier(ref.field)
        f = self.fld(ref)
        return naming.field_identifier(f.name, f.pattern)

    def s(self, ref: FieldRef) -> str:
        self.read.add((ref.message, ref.field))
        side = self.src
        return f"{side.var(ref.message)}.{self.attr(ref)}"

    def t(self, ref: FieldRef) -> str:
        self.written.add((ref.message, ref.field))
        return f"{self.dst.var(ref.message)}.{self.attr(ref)}"

    def label(self, ref: FieldRef) -> str:
        return lit(f"{ref.message}.{ref.field}")

    def const(self, text: str) -> str:
        self._counter += 1
        name = f"_K{self._counter}_{self.name}"
        self.module_consts.append(f"{name} = {text}")
        return name

    def emit(self, *lines: str, indent: int = 1) -> None:
        pad = "    " * indent
        self.lines.extend(pad + line if line else "" for line in lines)

    def constant_value(self, name: str, refs: Iterable[FieldRef]) -> int | float | bool | str:
        """A constant by name, looked up in the messages a rule uses, then in dialect enums."""
        for ref in refs:
            if ref.message != CONCEPTS_ENDPOINT:
                for c in self.msg(ref.message).constants:
                    if c.name == name:
                        return c.value
        for e in self.schema.enums:
            for entry in e.entries:
                if entry.name == name:
                    return entry.value
        raise BattgenError(f"{self.mapping.name}: no constant {name!r}")

    def value_of(self, value: ParamValue, refs: Iterable[FieldRef]) -> object:
        """A param as a Python value: UPPER_CASE names are constants, NaN text is NaN."""
        if isinstance(value, str) and value.isupper() and value.replace("_", "").isalnum():
            return self.constant_value(value, refs)
        if isinstance(value, str) and value.lower() == "nan":
            return math.nan
        return value

    def markers(self, f: Field, rule: Rule) -> list[float | int]:
        """The values meaning "unknown" for a field: its IR sentinel, then the rule's own."""
        out: list[float | int] = []
        if f.invalid is not None:
            out.append(f.invalid.value)
        extra = params(rule).get("unknown", ())
        for v in extra if isinstance(extra, tuple) else (extra,):
            if not isinstance(v, Param):
                out.append(marker_value(v))
        return out

    def known_test(self, var: str, marks: list[float | int]) -> list[str]:
        tests = []
        for m in marks:
            if isinstance(m, float) and math.isnan(m):
                tests.append(f"{var} == {var}")
            else:
                tests.append(f"{var} != {lit(m)}")
        return tests

    def factor(self, frm: Unit | None, to: Unit | None) -> tuple[float, float]:
        if frm is None or to is None:
            return 1.0, 0.0
        return frm.factor_to(to)

    def unit_of(self, ref: FieldRef) -> Unit | None:
        if ref.message == CONCEPTS_ENDPOINT:
            return self.concepts[ref.field].unit
        return self.fld(ref).unit

    def prim(self, f: Field) -> PrimitiveType | None:
        t = f.type
        while isinstance(t, ArrayType):
            t = t.element
        return t if isinstance(t, PrimitiveType) else None

    def store(self, f: Field, expr: str, label: str, hi: float | None = None) -> str:
        """Source converting a float value to what the field holds (quantised, rounded, clamped)."""
        p = self.prim(f)
        if p is None:
            return expr
        if p.kind is PrimitiveKind.FLOAT:
            if p.bits == 16:
                return f"_r.f16({expr}, rep, {label})"
            if p.bits == 32:
                return f"_r.f32({expr})"
            return expr
        if p.kind is PrimitiveKind.BOOL:
            return f"bool({expr})"
        rng = p.value_range
        if rng is None:
            return expr
        top = int(rng[1]) if hi is None else min(int(rng[1]), int(hi))
        return f"_r.to_int({expr}, {lit(int(rng[0]))}, {lit(top)}, rep, {label})"

    def affine(self, expr: str, mul: float, add: float) -> str:
        out = expr
        if mul != 1.0:
            out = f"{out} * {num(mul)}"
        if add != 0.0:
            out = f"{out} + {num(add)}"
        return out

    # -- direction helpers -----------------------------------------------------------------

    def flow(self, rule: Rule) -> tuple[tuple[FieldRef, ...], tuple[FieldRef, ...]]:
        """(read refs, written refs) for this function's direction."""
        return (rule.targets, rule.sources) if self.backward else (rule.sources, rule.targets)

    def applies(self, rule: Rule) -> bool:
        only = params(rule).get("only")
        return only is None or (only == "backward") == self.backward

    # -- the function ----------------------------------------------------------------------

    def build(self) -> list[str]:
        body_start = len(self.lines)
        for rule in self.mapping.rules:
            if not self.applies(rule):
                continue
            reads, _ = self.flow(rule)
            optional = sorted(
                {
                    self.src.var(r.message)
                    for r in reads
                    if r.message != CONCEPTS_ENDPOINT and self.src.optional(r.message)
                }
            )
            emitter: Callable[[Rule], None] = getattr(self, f"op_{rule.op}")
            before = len(self.lines)
            emitter(rule)
            self._counter += 1
            block = [_TEMP.sub(lambda m: f"{m.group(0)}{self._counter}", line) for line in self.lines[before:]]
            del self.lines[before:]
            if optional and rule.op not in _HANDLES_MISSING:
                self.emit(f"if {' and '.join(f'{v} is not None' for v in optional)}:")
                self.lines.extend("    " + line if line else "" for line in block)
            else:
                self.lines.extend(block)
        self.epilogue()
        body = self.lines[body_start:]
        del self.lines[body_start:]
        return body

    def epilogue(self) -> None:
        """Loss reporting that depends on the whole function: dropped bits, dropped source fields,
        target fields no rule wrote, and (for pair mappings) target fields left at their marker."""
        for (qualified, fname), mask in sorted(self.bit_masks.items()):
            ref = FieldRef(qualified, fname)
            var = f"{self.src.var(qualified)}.{self.attr(ref)}"
            guard = f"rep_d is not None and {var} & {lit(~mask)}"
            if self.src.optional(qualified):
                guard = f"{self.src.var(qualified)} is not None and {guard}"
            self.emit(
                f"if {guard}:",
                f"    rep_d.dropped({self.label(ref)}, 'bits %#x have no counterpart' % ({var} & {lit(~mask)}))",
            )
        # source information nobody read
        if self.src.endpoint is None:
            unused = [c for c in self.concepts if (CONCEPTS_ENDPOINT, c) not in self.read]
            if unused:
                names = self.const(lit(tuple(unused)))
                self.emit(
                    "if rep_d is not None:",
                    f"    for _n in {names}:",
                    f"        if getattr({self.src.names[0]}, _n) is not None:",
                    "            rep_d.dropped('concepts.' + _n)",
                )
        else:
            for qualified, var in zip(self.src.endpoint.messages, self.src.names, strict=True):
                m = self.msg(qualified)
                attrs = tuple(
                    (naming.field_identifier(f.name, f.pattern), f.name)
                    for f in m.fields
                    if not f.is_padding and (qualified, f.name) not in self.read
                )
                if not attrs:
                    continue
                names = self.const(lit(attrs))
                default = self.const(f"{self.classes[qualified]}()")
                guard = "rep_d is not None" + (f" and {var} is not None" if self.src.optional(qualified) else "")
                self.emit(
                    f"if {guard}:",
                    f"    for _a, _n in {names}:",
                    f"        if _r.differs(getattr({var}, _a), getattr({default}, _a)):",
                    f"            rep_d.dropped({lit(qualified + '.')} + _n)",
                )
        if self.dst.endpoint is None:
            return
        pair = self.src.endpoint is not None
        for qualified, var in zip(self.dst.endpoint.messages, self.dst.names, strict=True):
            m = self.msg(qualified)
            unwritten = tuple(f.name for f in m.fields if not f.is_padding and (qualified, f.name) not in self.written)
            if unwritten:
                names = self.const(lit(tuple(f"{qualified}.{n}" for n in unwritten)))
                self.emit("if rep_u is not None:", f"    for _n in {names}:", "        rep_u.unknown(_n)")
            if not pair:
                continue
            for f in m.fields:
                if f.invalid is None or (qualified, f.name) not in self.written:
                    continue
                a = f"{var}.{naming.field_identifier(f.name, f.pattern)}"
                mark = num(f.invalid.value) if isinstance(f.invalid.value, float) else lit(f.invalid.value)
                test = (
                    f"all(_r.is_marker(_x, {mark}) for _x in {a})"
                    if f.invalid.per_element
                    else f"_r.is_marker({a}, {mark})"
                )
                self.emit(f"if rep_u is not None and {test}:", f"    rep_u.unknown({lit(qualified + '.' + f.name)})")

    # -- strict ops (format <-> concepts) ---------------------------------------------------

    def _format_and_concept(self, rule: Rule) -> tuple[FieldRef, FieldRef]:
        fmt, con = rule.sources[0], rule.targets[0]
        if fmt.message == CONCEPTS_ENDPOINT:
            fmt, con = con, fmt
        return fmt, con

    def op_scale(self, rule: Rule) -> None:
        fmt, con = self._format_and_concept(rule)
        f = self.fld(fmt)
        p = params(rule)
        marks = self.markers(f, rule)
        f_unit = f.unit or self.concepts[con.field].unit
        c_unit = self.concepts[con.field].unit
        is_list = isinstance(f.type, ArrayType)
        if not self.backward:
            mul, add = self.factor(f_unit, c_unit)
            src = self.s(fmt)
            self.emit(f"_v = _r.dt_first({src})" if is_list else f"_v = {src}")
            tests = ["_v is not None"] if is_list else []
            tests += self.known_test("_v", marks)
            if "valid_above" in p:
                tests.append(f"_v > {lit(p['valid_above'])}")
            if "valid_max" in p:
                tests.append(f"_v <= {lit(p['valid_max'])}")
            value = self.affine("float(_v)", mul, add)
            if tests:
                self.emit(f"if {' and '.join(tests)}:", f"    {self.t(con)} = {value}")
            else:
                self.emit(f"{self.t(con)} = {value}")
            return
        mul, add = self.factor(c_unit, f_unit)
        label = self.label(fmt)
        target = self.t(fmt)
        self.emit(f"_v = {self.s(con)}")
        self.emit("if _v is None or _v != _v:")
        if marks:
            self.emit(f"    {target} = {self._marker_literal(f, marks[0])}")
        self.emit("    if rep_u is not None:", f"        rep_u.unknown({label})", "else:")
        hi = p.get("valid_max")
        value = self.store(f, self.affine("_v", mul, add), label, hi if isinstance(hi, int | float) else None)
        if is_list:
            value = f"[[{value}]]"
        self.emit(f"    {target} = {value}")
        int_marks = [m for m in marks if not (isinstance(m, float) and math.isnan(m))]
        if int_marks and not is_list:
            self.emit(
                f"    if rep is not None and {target} in {lit(tuple(int_marks))}:",
                f"        rep.clamped({label}, 'a known value written as the unknown marker')",
            )

    def _marker_literal(self, f: Field, mark: float | int) -> str:
        p = self.prim(f)
        if p is not None and p.kind is PrimitiveKind.FLOAT:
            return num(float(mark))
        return lit(int(mark))

    def op_copy(self, rule: Rule) -> None:
        fmt, con = self._format_and_concept(rule)
        f = self.fld(fmt)
        p = params(rule)
        add = p.get("add", 0)
        marks = self.markers(f, rule)
        kind = self.concepts[con.field].kind
        text = kind == "text"
        if not self.backward:
            self.emit(f"_v = {self.s(fmt)}")
            if text:
                self.emit(f"{self.t(con)} = _r.text_in(_v)")
                return
            value = "bool(_v)" if kind == "bool" else f"_v + {lit(add)}" if add else "_v"
            tests = self.known_test("_v", marks)
            if tests:
                self.emit(f"if {' and '.join(tests)}:", f"    {self.t(con)} = {value}")
            else:
                self.emit(f"{self.t(con)} = {value}")
            return
        label = self.label(fmt)
        target = self.t(fmt)
        self.emit(f"_v = {self.s(con)}", "if _v is None:")
        if marks:
            self.emit(f"    {target} = {self._marker_literal(f, marks[0])}")
        self.emit("    if rep_u is not None:", f"        rep_u.unknown({label})", "else:")
        if text:
            cap = f.type.capacity if isinstance(f.type, ArrayType | StringType) else None
            if isinstance(f.type, StringType):
                self.emit(f"    {target} = _v")
            else:
                self.emit(f"    {target} = _r.bytes_out(_v, {lit(cap)}, rep, {label})")
            return
        value = f"_v - {lit(add)}" if add else "_v"
        self.emit(f"    {target} = {self.store(f, value, label)}")
        if marks and kind != "bool":
            self.emit(
                f"    if rep is not None and {target} in {lit(tuple(marks))}:",
                f"        rep.clamped({label}, 'a known value written as the unknown marker')",
            )

    def op_const(self, rule: Rule) -> None:
        value = self.value_of(params(rule).get("value"), rule.targets)
        for ref in rule.targets:
            if ref.message != CONCEPTS_ENDPOINT:
                p = self.prim(self.fld(ref))
                if p is not None and p.kind is PrimitiveKind.FLOAT and isinstance(value, int | float):
                    value = float(value)
                if isinstance(value, str) and p is not None and p.kind is PrimitiveKind.UINT:
                    value = value.encode("utf-8")
            self.emit(f"{self.t(ref)} = {num(value) if isinstance(value, float) else lit(value)}")

    def _mask(self, name: ParamValue, refs: Iterable[FieldRef]) -> int:
        """A constant as a mask: bit masks as they are, bit indices (uORB FAULT_*) as 1 << i."""
        value = self.constant_value(str(name), refs)
        for ref in refs:
            if ref.message == CONCEPTS_ENDPOINT:
                continue
            for e in self.msg(ref.message).enums:
                if any(x.name == name for x in e.entries) and e.kind.value == "bit_index":
                    return 1 << int(value)
        return int(value)

    def op_flag(self, rule: Rule) -> None:
        fmt, con = self._format_and_concept(rule)
        mask = self._mask(params(rule)["mask"], [fmt])
        if not self.backward:
            key = (fmt.message, fmt.field)
            self.bit_masks[key] = self.bit_masks.get(key, 0) | mask
            self.emit(f"{self.t(con)} = bool({self.s(fmt)} & {lit(mask)})")
        else:
            target = self.t(fmt)
            self.emit(f"if {self.s(con)}:", f"    {target} |= {lit(mask)}")

    def op_flag_choice(self, rule: Rule) -> None:
        """A bit that stands for one value of a choice concept (CHARGING -> warning 'charging')."""
        fmt, con = self._format_and_concept(rule)
        p = params(rule)
        mask = self._mask(p["mask"], [fmt])
        value = lit(p["value"])
        if not self.backward:
            key = (fmt.message, fmt.field)
            self.bit_masks[key] = self.bit_masks.get(key, 0) | mask
            self.emit(f"if {self.s(fmt)} & {lit(mask)}:", f"    {self.t(con)} = {value}")
        else:
            self.emit(f"if {self.s(con)} == {value}:", f"    {self.t(fmt)} |= {lit(mask)}")

    def op_flags(self, rule: Rule) -> None:
        fmt, con = self._format_and_concept(rule)
        concept = self.concepts[con.field]
        table = {k: self._mask(v, [fmt]) for k, v in pairs(params(rule)["map"])}
        ordered = [(c, table[c]) for c in concept.choices if c in table]
        if not self.backward:
            key = (fmt.message, fmt.field)
            self.bit_masks[key] = self.bit_masks.get(key, 0) | sum(table.values())
            self.emit(f"_v = {self.s(fmt)}")
            items = ", ".join(f"({lit(n)}, {lit(m)})" for n, m in ordered)
            self.emit(f"{self.t(con)} = tuple(_n for _n, _m in ({items},) if _v & _m)")
            return
        target, label = self.t(fmt), self.label(fmt)
        known = self.const(lit(tuple(sorted(table))))
        self.emit(
            f"_v = {self.s(con)}", "if _v is None:", "    if rep_u is not None:", f"        rep_u.unknown({label})"
        )
        self.emit("else:", f"    _b = {target}")
        for n, m in ordered:
            self.emit(f"    if {lit(n)} in _v:", f"        _b |= {lit(m)}")
        self.emit(
            f"    {target} = _b",
            "    if rep_d is not None:",
            "        for _n in _v:",
            f"            if _n not in {known}:",
            f"                rep_d.dropped({lit('concepts.' + con.field)}, _n + ' has no counterpart')",
        )

    def op_choice(self, rule: Rule) -> None:
        fmt, con = self._format_and_concept(rule)
        p = params(rule)
        table = [(k, self.value_of(v, [fmt])) for k, v in pairs(p["map"])]
        unknown = self.value_of(p["unknown"], [fmt]) if "unknown" in p else None
        if not self.backward:
            fwd = self.const("dict((" + ", ".join(f"({lit(v)}, {lit(k)})" for k, v in table) + ",))")
            self.emit(f"_v = {self.s(fmt)}", f"{self.t(con)} = None if _v is None else {fwd}.get(_v)")
            skip = [lit(x) for x in (None, unknown)]
            self.emit(
                f"if rep_d is not None and _v not in {fwd} and _v not in ({', '.join(skip)},):",
                f"    rep_d.dropped({self.label(fmt)}, '%r has no counterpart' % (_v,))",
            )
            return
        back = self.const("dict((" + ", ".join(f"({lit(k)}, {lit(v)})" for k, v in table) + ",))")
        target, label = self.t(fmt), self.label(fmt)
        self.emit(f"_v = {self.s(con)}", f"_w = None if _v is None else {back}.get(_v)")
        self.emit("if _w is not None:", f"    {target} = _w", "else:")
        if unknown is not None:
            self.emit(f"    {target} = {lit(unknown)}")
        self.emit(
            "    if rep_u is not None:",
            f"        rep_u.unknown({label})",
            "    if rep_d is not None and _v is not None:",
            f"        rep_d.dropped({lit('concepts.' + con.field)}, '%r has no counterpart' % (_v,))",
        )

    def op_cells(self, rule: Rule) -> None:
        fmt, con = self._format_and_concept(rule)
        f = self.fld(fmt)
        assert isinstance(f.type, ArrayType)
        p = params(rule)
        count = p.get("count_field")
        mark = f.invalid.value if f.invalid is not None and f.invalid.per_element else None
        f_unit = f.unit or self.concepts[con.field].unit
        c_unit = self.concepts[con.field].unit
        count_ref = FieldRef(fmt.message, str(count)) if count else None
        if not self.backward:
            mul, add = self.factor(f_unit, c_unit)
            self.emit(f"_c = list({self.s(fmt)})")
            if count_ref is not None:
                self.emit(f"_n = {self.s(count_ref)}", f"_c = _c[:_n] if _n else _r.leading(_c, {lit(mark)})")
            elif mark is not None:
                self.emit(f"_c = _r.leading(_c, {lit(mark)})")
            conv = self.affine("float(_x)", mul, add)
            if mark is not None:
                conv = f"math.nan if _r.is_marker(_x, {lit(mark)}) else {conv}"
            self.emit(f"{self.t(con)} = tuple({conv} for _x in _c) or None")
            return
        mul, add = self.factor(c_unit, f_unit)
        target, label = self.t(fmt), self.label(fmt)
        cap = f.type.capacity
        self.emit(
            f"_c = {self.s(con)}", "if _c is None:", "    if rep_u is not None:", f"        rep_u.unknown({label})"
        )
        self.emit("else:")
        if cap is not None:
            self.emit(
                f"    if len(_c) > {cap}:",
                "        if rep is not None:",
                f"            rep.clamped({label}, '%d cells, room for {cap}' % len(_c))",
                f"        _c = _c[:{cap}]",
            )
        elem = self.store(f, self.affine("_x", mul, add), label)
        if mark is not None:
            elem = f"{self._marker_literal(f, mark)} if _x != _x else {elem}"
        self.emit(f"    _l = [{elem} for _x in _c]")
        if not f.type.dynamic and cap is not None:
            fill = self._marker_literal(f, mark) if mark is not None else ("0.0" if self._is_float(f) else "0")
            self.emit(f"    _l += [{fill}] * ({cap} - len(_l))")
        self.emit(f"    {target} = _l")
        if count_ref is not None:
            ct = self.t(count_ref)
            self.emit(
                f"    if not {ct}:",
                f"        {ct} = min(len(_c), {cap})",
                "        if rep_u is not None:",
                f"            rep_u.discard('unknown', {self.label(count_ref)})",
            )

    def _is_float(self, f: Field) -> bool:
        p = self.prim(f)
        return p is not None and p.kind is PrimitiveKind.FLOAT

    def op_mavlink_voltages(self, rule: Rule) -> None:
        main_ref, ext_ref = rule.sources
        pack, cells = rule.targets
        main_f, ext_f = self.fld(main_ref), self.fld(ext_ref)
        assert isinstance(main_f.type, ArrayType) and isinstance(ext_f.type, ArrayType)
        main_mark = int(main_f.invalid.value) if main_f.invalid is not None else 0xFFFF
        ext_mark = int(ext_f.invalid.value) if ext_f.invalid is not None else 0
        v_unit = self.concepts[pack.field].unit
        if not self.backward:
            mul, add = self.factor(main_f.unit, v_unit)
            self.emit(
                f"_c, _p = _r.mavlink_cells_in({self.s(main_ref)}, {self.s(ext_ref)},"
                f" {main_mark}, {ext_mark}, {main_mark - 1})",
                "if _p is not None:",
                f"    {self.t(pack)} = {self.affine('float(_p)', mul, add)}",
                "if _c is not None:",
                f"    {self.t(cells)} = tuple({self.affine('float(_x)', mul, add)} for _x in _c)",
            )
            return
        mul, add = self.factor(v_unit, main_f.unit)
        self.emit(
            f"_c = {self.s(cells)}",
            f"_p = {self.s(pack)}",
            f"{self.t(main_ref)}, {self.t(ext_ref)} = _r.mavlink_cells_out(",
            f"    None if _c is None else [{self.affine('_x', mul, add)} for _x in _c],",
            f"    None if _p is None else {self.affine('_p', mul, add)},",
            f"    {main_f.type.capacity}, {ext_f.type.capacity}, {main_mark}, {ext_mark},",
            f"    rep, {self.label(main_ref)}, {self.label(ext_ref)},",
            ")",
        )

    def op_soc_hybrid(self, rule: Rule) -> None:
        rem, full, pct = rule.sources
        f = self.fld(pct)
        p = params(rule)
        mul, add = self.factor(f.unit, self.concepts[rule.targets[0].field].unit)
        tests = self.known_test("_p", self.markers(f, rule))
        if "valid_max" in p:
            tests.append(f"_p <= {lit(p['valid_max'])}")
        target = self.t(rule.targets[0])
        self.emit(
            f"_e, _f, _p = {self.s(rem)}, {self.s(full)}, {self.s(pct)}",
            "if _e == _e and _f == _f and _e > 0 and _f > 0:",
            f"    {target} = min(_e / _f, 1.0)",
            f"elif {' and '.join(tests) or 'True'}:",
            f"    {target} = {self.affine('float(_p)', mul, add)}",
        )

    def op_dt_pack(self, rule: Rule) -> None:
        vmax, vmin, chem = rule.sources
        count, nominal = rule.targets
        p = params(rule)
        tables = [
            self.const("dict(" + lit(tuple(pairs(p[k]))) + ")")
            for k in ("cell_charged_v", "cell_empty_v", "cell_nominal_v")
        ]
        mul_max, _ = self.factor(self.fld(vmax).unit, units.lookup("V"))
        mul_min, _ = self.factor(self.fld(vmin).unit, units.lookup("V"))
        self.emit(
            f"_hi = _r.dt_first({self.s(vmax)})",
            f"_lo = _r.dt_first({self.s(vmin)})",
            f"_ch = {self.s(chem)}",
            "_n = _r.cells_from_design(",
            f"    None if _hi is None else _hi * {num(mul_max)}, None if _lo is None else _lo * {num(mul_min)},",
            f"    _ch, {tables[0]}, {tables[1]},",
            ")",
            "if _n is not None:",
            f"    {self.t(count)} = _n",
            f"    if _ch is not None and _ch in {tables[2]}:",
            f"        {self.t(nominal)} = _n * {tables[2]}[_ch]",
        )

    def op_ocv_soc(self, rule: Rule) -> None:
        temps, tables = rule.sources
        p = params(rule)
        v_in, t_in = str(p["voltage_input"]), str(p["temperature_input"])
        for name in (v_in, t_in):
            ident = naming.identifier(name)
            if ident not in self.inputs:
                self.inputs.append(ident)
        to_uv, _ = self.factor(units.lookup("V"), units.lookup("uV"))
        pct, _ = self.factor(units.lookup("%"), self.concepts[rule.targets[0].field].unit)
        tf = self.fld(tables)
        stem = (tf.pattern or tf.name).strip("^$").split("[", 1)[0]
        self.emit(
            f"_ts = {self.s(temps)}",
            f"_tb = {self.s(tables)}",
            f"if {naming.identifier(v_in)} is not None and _ts:",
            f"    _tabs = [_x for _x in (_tb.get({lit(stem)} + str(_i)) for _i in range(len(_ts))) if _x]",
            f"    _t = {naming.identifier(t_in)}",
            "    if _t is None and len(_ts) == 1:",
            "        _t = _ts[0]",
            "    if _t is not None and len(_tabs) == len(_ts):",
            f"        _uv = int(round({naming.identifier(v_in)} * {num(to_uv)}))",
            "        _cap = _r.ocv_to_capacity(_tabs, _ts, _uv, int(round(_t)))",
            f"        {self.t(rule.targets[0])} = _cap * {num(pct)}",
        )

    def op_same_names(self, rule: Rule) -> None:
        src_m = self.msg(rule.sources[0].message)
        dst_m = self.msg(rule.targets[0].message)
        dst_names = {f.name: f for f in dst_m.fields}
        for f in src_m.fields:
            g = dst_names.get(f.name)
            if f.is_padding or g is None:
                continue
            value = self.s(FieldRef(src_m.qualified_name, f.name))
            if isinstance(f.type, ArrayType):
                value = f"list({value})"
            self.emit(f"{self.t(FieldRef(dst_m.qualified_name, g.name))} = {value}")

    # -- px4 ops (pair mappings, one way) ---------------------------------------------------

    def op_zero_all(self, rule: Rule) -> None:
        for ref in rule.targets:
            m = self.msg(ref.message)
            var = self.dst.var(ref.message)
            for f in m.fields:
                if f.invalid is None or f.is_padding:
                    continue
                zero = "0.0" if self._is_float(f) else "0"
                if isinstance(f.type, ArrayType) and f.type.capacity is not None and not f.type.dynamic:
                    zero = f"[{zero}] * {f.type.capacity}"
                self.emit(f"{var}.{naming.field_identifier(f.name, f.pattern)} = {zero}")

    def _unit_param(self, p: dict[str, ParamValue], key: str, fallback: Unit | None) -> Unit | None:
        if key in p:
            u = units.lookup(str(p[key]))
            if u is None:
                raise BattgenError(f"{self.mapping.name}: unknown unit {p[key]!r}")
            return u
        return fallback

    def _store_c(self, f: Field, expr: str, label: str) -> str:
        """A C assignment of a float32 value to the field's type, then DroneCAN saturation."""
        p = self.prim(f)
        assert p is not None
        if p.kind is PrimitiveKind.FLOAT:
            return f"_r.f16({expr}, rep, {label})" if p.bits == 16 else expr
        if p.kind is PrimitiveKind.BOOL:
            return f"bool({expr})"
        signed = p.kind is PrimitiveKind.INT
        storage = next(b for b in (8, 16, 32, 64) if b >= p.bits)
        out = f"_r.c_float_to_int({expr}, {storage}, {signed}, rep, {label})"
        if storage != p.bits:
            lo, hi = p.value_range or (0, 0)
            out = f"_r.saturate({out}, {int(lo)}, {int(hi)})"
        return out

    def px4_read(self, ref: FieldRef, expr: str | None = None) -> str:
        """A source value as PX4 holds it in a C float: a DroneCAN float16 as it came off the wire."""
        value = expr or self.s(ref)
        p = self.prim(self.fld(ref))
        if p is not None and p.kind is PrimitiveKind.FLOAT and p.bits == 16:
            return f"_r.f16(float({value}), None, '')"
        return f"_r.f32(float({value}))"

    def op_px4_convert(self, rule: Rule) -> None:
        src, dst = rule.sources[0], rule.targets[0]
        p = params(rule)
        f_dst = self.fld(dst)
        label = self.label(dst)
        self.emit(f"_x = {self.px4_read(src)}")
        if p.get("convert") == "units":
            su = self._unit_param(p, "source_unit", self.fld(src).unit)
            tu = self._unit_param(p, "target_unit", f_dst.unit)
            if su is None or tu is None:
                raise BattgenError(f"{self.mapping.name}: {src.field} -> {dst.field} needs units on both sides")
            mul, add = su.factor_to(tu)
            if mul != 1.0:
                if p.get("form") == "divide":
                    self.emit(f"_x = _r.f32(_x / {num(_f32(1.0 / mul))})")
                else:
                    self.emit(f"_x = _r.f32(_x * {num(_f32(mul))})")
            if add != 0.0:
                self.emit(f"_x = _r.f32(_x + {num(_f32(add))})")
        if p.get("round"):
            self.emit("_x = _r.roundf(_x)")
        value = self._store_c(f_dst, "_x", label)
        if "at_least" in p:
            value = f"max({value}, {lit(p['at_least'])})"
        tests = []
        if "guard" in p:
            tests.append(self.s(FieldRef(src.message, str(p["guard"]))))
        if p.get("finite"):
            tests.append("math.isfinite(_x)")
        if "above" in p:
            tests.append(f"_x > {num(_f32(float(p['above'])))}")  # type: ignore[arg-type]
        target = self.t(dst)
        if tests:
            otherwise = self.value_of(p.get("otherwise", 0), [dst])
            other = num(otherwise) if isinstance(otherwise, float) else lit(otherwise)
            self.emit(f"{target} = {value} if {' and '.join(tests)} else {other}")
        else:
            self.emit(f"{target} = {value}")

    def op_px4_int(self, rule: Rule) -> None:
        src, dst = rule.sources[0], rule.targets[0]
        p = params(rule)
        expr = f"int({self.s(src)})"
        if "mask" in p:
            expr = f"({expr} & {lit(self._mask(p['mask'], [src]))})"
        if p.get("add"):
            expr = f"{expr} + {lit(p['add'])}"
        f = self.fld(dst)
        prim = self.prim(f)
        assert prim is not None
        if prim.kind is PrimitiveKind.BOOL:
            self.emit(f"{self.t(dst)} = bool({expr})")
            return
        signed = prim.kind is PrimitiveKind.INT
        storage = next(b for b in (8, 16, 32, 64) if b >= prim.bits)
        value = f"_r.c_wrap({expr}, {storage}, {signed})"
        if storage != prim.bits:
            lo, hi = prim.value_range or (0, 0)
            value = f"_r.saturate({value}, {int(lo)}, {int(hi)})"
        self.emit(f"{self.t(dst)} = {value}")

    def op_px4_warning(self, rule: Rule) -> None:
        dst = rule.targets[0]
        p = params(rule)
        of = self.t(FieldRef(dst.message, str(p["of"])))
        names = {k: f"WARNING_{k.upper()}" for k in ("emergency", "critical", "low", "none")}
        vals = {k: self.constant_value(v, [dst]) for k, v in names.items()}
        self.emit(
            f"_s = {of}",
            f"{self.t(dst)} = (",
            f"    {lit(vals['emergency'])} if _s < {num(_f32(float(p['emergency'])))}"  # type: ignore[arg-type]
            f" else {lit(vals['critical'])} if _s < {num(_f32(float(p['critical'])))}"  # type: ignore[arg-type]
            f" else {lit(vals['low'])} if _s < {num(_f32(float(p['low'])))}"  # type: ignore[arg-type]
            f" else {lit(vals['none'])}",
            ")",
        )

    def op_enum_map(self, rule: Rule) -> None:
        src, dst = rule.sources[0], rule.targets[0]
        p = params(rule)
        table = [(self.value_of(k, [src]), self.value_of(v, [dst])) for k, v in pairs(p["map"])]
        default = self.value_of(p.get("default", 0), [dst])
        const = self.const("dict((" + ", ".join(f"({lit(k)}, {lit(v)})" for k, v in table) + ",))")
        self.emit(f"{self.t(dst)} = {const}.get({self.s(src)}, {lit(default)})")

    def op_bits_from(self, rule: Rule) -> None:
        dst = rule.targets[0]
        self.emit("_b = 0")
        for mask_name, spec in pairs(params(rule)["bits"]):
            conf = dict(pairs(spec))
            src = FieldRef(rule.sources[0].message, str(conf["field"]))
            cond = self.s(src)
            if "equals" in conf:
                cond = f"{cond} == {lit(self.value_of(conf['equals'], [src]))}"
            self.emit(f"if {cond}:", f"    _b |= {lit(self._mask(mask_name, [dst]))}")
        self.emit(f"{self.t(dst)} = _b")

    def op_px4_stream_cells(self, rule: Rule) -> None:
        volt, cells, count, connected = rule.sources
        main, ext = rule.targets
        mf, ef = self.fld(main), self.fld(ext)
        assert isinstance(mf.type, ArrayType) and isinstance(ef.type, ArrayType)
        mul, _ = self.factor(self.fld(cells).unit, mf.unit)
        fill = int(mf.invalid.value) if mf.invalid is not None else 0xFFFF
        threshold = _f32(float(params(rule).get("cell_threshold", 0.0001)))  # type: ignore[arg-type]
        self.emit(
            f"{self.t(main)}, {self.t(ext)} = _r.px4_stream_cells(",
            f"    {self.s(volt)}, {self.s(cells)}, {self.s(count)}, {self.s(connected)},",
            f"    {num(_f32(mul))}, {num(threshold)}, {mf.type.capacity}, {ef.type.capacity}, {fill}, 0,",
            f"    rep, {self.label(main)},",
            ")",
        )

    def op_px4_receiver_cells(self, rule: Rule) -> None:
        (volts,) = rule.sources
        cells, count, total = rule.targets
        vf, cf = self.fld(volts), self.fld(cells)
        assert isinstance(cf.type, ArrayType) and isinstance(vf.type, ArrayType)
        mul, _ = self.factor(vf.unit, cf.unit)
        mark = int(vf.invalid.value) if vf.invalid is not None else 0xFFFF
        self.emit(
            f"_c, _n, _t = _r.px4_receiver_cells({self.s(volts)}, {cf.type.capacity}, {mark}, {num(_f32(1.0 / mul))})",
            f"{self.t(cells)} = _c",
            f"{self.t(count)} = _n",
            f"{self.t(total)} = _t",
        )

    def op_px4_bridge_cells(self, rule: Rule) -> None:
        volt, aux_cells = rule.sources
        cells, count = rule.targets
        cf = self.fld(cells)
        assert isinstance(cf.type, ArrayType)
        cap = cf.type.capacity
        aux_var = self.src.var(aux_cells.message)
        target = self.t(cells)
        self.emit(
            f"_c = [0.0] * {cap}",
            f"_c[0] = {self.px4_read(volt)}",
            f"if {aux_var} is None:",
            f"    {self.t(count)} = 1",
            "else:",
            f"    _a = {self.s(aux_cells)}",
            f"    _n = min(len(_a) & 0xFF, {cap})",
            "    for _i in range(_n):",
            f"        _c[_i] = {self.px4_read(aux_cells, '_a[_i]')}",
            f"    {self.t(count)} = _n",
            f"{target} = _c",
        )

    def op_px4_cell_list(self, rule: Rule) -> None:
        cells, count = rule.sources
        dst = rule.targets[0]
        cf = self.fld(cells)
        assert isinstance(cf.type, ArrayType)
        cap = cf.type.capacity
        label = self.label(dst)
        elem = self._store_c(self.fld(dst), "_r.f32(_x)", label)
        self.emit(
            f"_n = {self.s(count)}",
            f"if _n > {cap} and rep is not None:",
            f"    rep.clamped({label}, '%d cells, %d in the array' % (_n, {cap}))",
            f"{self.t(dst)} = [{elem} for _x in {self.s(cells)}[:min(_n, {cap})]]",
        )

    def op_px4_aux_capacity(self, rule: Rule) -> None:
        fcc, nv = rule.sources
        dst = rule.targets[0]
        f_dst = self.fld(dst)
        # Wh / V is Ah; the factor to the target's unit (mAh) comes from the unit registry
        ah = units.lookup("Ah")
        mul, _ = self.factor(ah, f_dst.unit)
        eps = _f32(float(params(rule).get("above", FLT_EPS)))  # type: ignore[arg-type]
        value = f"_r.f32(_r.f32({self.px4_read(fcc)} * {num(_f32(mul))}) / _v)"
        self.emit(
            f"_v = {self.px4_read(nv)}",
            f"if _v > {num(eps)}:",
            f"    {self.t(dst)} = {self._store_c(f_dst, value, self.label(dst))}",
        )

"""Emitters of the numeric ops between a format field and a concept: scale, copy, const, soc_hybrid.

Reading (forward), a field's value becomes the concept's unit unless it is one of its unknown
markers; writing (backward), unknown becomes the marker and a value is stored the way the field
holds it, with anything clamped or written as a marker reported.
"""

from __future__ import annotations

from ....ir import CONCEPTS_ENDPOINT, ArrayType, PrimitiveKind, Rule, StringType
from ....ir.ops import Const, Copy, Scale, SocHybrid
from ..literals import py_literal
from .context import RuleContext, affine, call, factor

_WRITTEN_AS_MARKER = py_literal("a known value written as the unknown marker")


class NumericEmitters(RuleContext):
    def visit_scale(self, rule: Rule, op: Scale) -> None:
        fmt, con = self.format_and_concept(rule)
        f = self.fld(fmt)
        marks = self.markers(f, op.unknown)
        c_unit = self.concepts[con.field].unit
        f_unit = f.unit or self.unit_param(op.unit, c_unit)
        is_list = isinstance(f.type, ArrayType)
        if not self.backward:
            mul, add = factor(f_unit, c_unit)
            if op.negate:
                mul, add = -mul, -add
            src = self.s(fmt)
            self.emit(f"_v = _cells.dt_first({src})" if is_list else f"_v = {src}")
            tests = ["_v is not None"] if is_list else []
            tests += self.known_test("_v", marks)
            if op.valid_above is not None:
                tests.append(f"_v > {py_literal(op.valid_above)}")
            if op.valid_max is not None:
                tests.append(f"_v <= {py_literal(op.valid_max)}")
            value = _signed(affine("float(_v)", mul, add), op.negate and add == 0.0)
            if tests:
                self.emit(f"if {' and '.join(tests)}:", f"    {self.t(con)} = {value}")
            else:
                self.emit(f"{self.t(con)} = {value}")
            return
        mul, add = factor(c_unit, f_unit)
        if op.negate:
            mul = -mul
        label = self.label(fmt)
        target = self.t(fmt)
        self.emit(f"_v = {self.s(con)}", "if _v is None or _v != _v:")
        if marks:
            self.emit(f"    {target} = {self.marker_literal(f, marks[0])}")
        self.emit("    if rep_u is not None:")
        self.emit_call("rep_u.unknown", [label], 2)
        self.emit("else:")
        stored = self.store(
            f, _signed(affine("_v", mul, add), op.negate and add == 0.0), label, op.valid_max, op.unknown
        )
        if is_list:  # a devicetree list of one
            self.emit_assign("_w", stored, 1)
            self.emit(f"    {target} = [[_w]]")
        else:
            self.emit_assign(target, stored, 1)
        int_marks = [m for m in marks if m == m]
        if int_marks and not is_list:
            self.emit(f"    if rep is not None and {target} in {py_literal(tuple(int_marks))}:")
            self.emit_call("rep.clamped", [label, _WRITTEN_AS_MARKER], 2)

    def visit_copy(self, rule: Rule, op: Copy) -> None:
        fmt, con = self.format_and_concept(rule)
        f = self.fld(fmt)
        add = op.add or 0
        marks = self.markers(f, op.unknown)
        kind = self.concepts[con.field].kind
        if not self.backward:
            self.emit(f"_v = {self.s(fmt)}")
            if kind == "text":
                self.emit(f"{self.t(con)} = _r.text_in(_v)")
                return
            value = "bool(_v)" if kind == "bool" else f"_v + {py_literal(add)}" if add else "_v"
            tests = self.known_test("_v", marks)
            if tests:
                self.emit(f"if {' and '.join(tests)}:", f"    {self.t(con)} = {value}")
            else:
                self.emit(f"{self.t(con)} = {value}")
            return
        label = self.label(fmt)
        target = self.t(fmt)
        self.emit(f"_v = {self.s(con)}", "if _v is None:")
        if kind == "text" and f.invalid is not None:  # a text's marker (MAVLink "[0]") is the empty text
            cap = f.type.capacity if isinstance(f.type, ArrayType) else None
            empty = '""' if isinstance(f.type, StringType) else f"bytes({py_literal(cap or 0)})"
            self.emit(f"    {target} = {empty}")
        elif marks:
            self.emit(f"    {target} = {self.marker_literal(f, marks[0])}")
        self.emit("    if rep_u is not None:")
        self.emit_call("rep_u.unknown", [label], 2)
        self.emit("else:")
        if kind == "text":
            cap = f.type.capacity if isinstance(f.type, ArrayType | StringType) else None
            out = "_r.text_out" if isinstance(f.type, StringType) else "_r.bytes_out"
            self.emit_assign(target, call(out, ["_v", py_literal(cap), "rep", label]), 1)
            return
        value = f"_v - {py_literal(add)}" if add else "_v"
        self.emit_assign(target, self.store(f, value, label, marks=op.unknown), 1)
        if marks and kind != "bool":
            self.emit(f"    if rep is not None and {target} in {py_literal(tuple(marks))}:")
            self.emit_call("rep.clamped", [label, _WRITTEN_AS_MARKER], 2)

    def visit_const(self, rule: Rule, op: Const) -> None:
        value = self.value_of(op.value, rule.targets)
        for ref in rule.targets:  # a value made a float (or bytes) for one target stays so for the next
            if ref.message != CONCEPTS_ENDPOINT:
                p = self.prim(self.fld(ref))
                if p is not None and p.kind is PrimitiveKind.FLOAT and isinstance(value, int | float):
                    value = float(value)
                if isinstance(value, str) and p is not None and p.kind is PrimitiveKind.UINT:
                    value = value.encode("utf-8")
            self.emit(f"{self.t(ref)} = {py_literal(value)}")

    def visit_soc_hybrid(self, rule: Rule, op: SocHybrid) -> None:
        remaining, full = rule.sources[:2]
        target = self.t(rule.targets[0])
        self.emit(
            f"_e = {self.s(remaining)}",
            f"_f = {self.s(full)}",
            "if _e == _e and _f == _f and _e > 0 and _f > 0:",
            f"    {target} = min(_e / _f, 1.0)",
        )
        if len(rule.sources) < 3:
            return
        percent = rule.sources[2]
        f = self.fld(percent)
        mul, add = factor(f.unit, self.concepts[rule.targets[0].field].unit)
        tests = self.known_test("_p", self.markers(f, op.unknown))
        if op.valid_max is not None:
            tests.append(f"_p <= {py_literal(op.valid_max)}")
        self.emit(
            "else:",
            f"    _p = {self.s(percent)}",
            f"    if {' and '.join(tests) or 'True'}:",
            f"        {target} = {affine('float(_p)', mul, add)}",
        )


def _signed(value: str, negated: bool) -> str:
    """A negated value plus 0.0, so that a zero reads 0.0 rather than -0.0."""
    return f"{value} + 0.0" if negated else value

"""Emitters of the cell-array ops between a format and the concepts: cells, mavlink_voltages."""

from __future__ import annotations

from ....ir import FieldRef, Rule
from ....ir.ops import Cells, MavlinkVoltages
from ..literals import py_literal
from .context import RuleContext, affine, array_type, factor


class CellEmitters(RuleContext):
    def visit_cells(self, rule: Rule, op: Cells) -> None:
        fmt, con = self.format_and_concept(rule)
        f = self.fld(fmt)
        array = array_type(f)
        mark = f.invalid.value if f.invalid is not None and f.invalid.per_element else None
        c_unit = self.concepts[con.field].unit
        f_unit = f.unit or c_unit
        count_ref = FieldRef(fmt.message, op.count_field) if op.count_field else None
        if not self.backward:
            mul, add = factor(f_unit, c_unit)
            self.emit(f"_c = list({self.s(fmt)})")
            if f.invalid is not None and f.invalid.first_decides:  # [X:]: X first means no cell is known
                self.emit(f"_c = [] if _c and _r.is_marker(_c[0], {py_literal(f.invalid.value)}) else _c")
            if count_ref is not None:
                self.emit(
                    f"_n = {self.s(count_ref)}", f"_c = _c[:_n] if _n else _cells.leading(_c, {py_literal(mark)})"
                )
            elif mark is not None:
                self.emit(f"_c = _cells.leading(_c, {py_literal(mark)})")
            conv = affine("float(_x)", mul, add)
            if mark is not None:
                conv = f"_math.nan if _r.is_marker(_x, {py_literal(mark)}) else {conv}"
            self.emit(f"{self.t(con)} = tuple({conv} for _x in _c) or None")
            return
        mul, add = factor(c_unit, f_unit)
        target, label = self.t(fmt), self.label(fmt)
        cap = array.capacity
        self.emit(f"_c = {self.s(con)}", "if _c is None:", "    if rep_u is not None:")
        self.emit_call("rep_u.unknown", [label], 2)
        self.emit("else:")
        if cap is not None:
            self.emit(f"    if len(_c) > {cap}:", "        if rep is not None:")
            self.emit_call("rep.clamped", [label, f'f"{{len(_c)}} cells, room for {cap}"'], 3)
            self.emit(f"        _c = _c[:{cap}]")

        def converted(name: str) -> str:
            elem = str(self.store(f, affine("_x", mul, add), name))
            if mark is not None:
                elem = f"{self.marker_literal(f, mark)} if _x != _x else {elem}"
            return f"    _l = [{elem} for _x in _c]"

        self.emit_with_label(converted, label)
        if not array.dynamic and cap is not None:
            fill = self.marker_literal(f, mark) if mark is not None else ("0.0" if self.is_float(f) else "0")
            self.emit(f"    _l += [{fill}] * ({cap} - len(_l))")
        self.emit(f"    {target} = _l")
        if count_ref is not None:
            count = self.t(count_ref)
            self.emit(f"    if not {count}:", f"        {count} = min(len(_c), {cap})", "        if rep_u is not None:")
            self.emit_call("rep_u.discard", [py_literal("unknown"), self.label(count_ref)], 3)

    def visit_mavlink_voltages(self, rule: Rule, op: MavlinkVoltages) -> None:
        main_ref, ext_ref = rule.sources
        pack, cells = rule.targets
        main_f, ext_f = self.fld(main_ref), self.fld(ext_ref)
        main_cap, ext_cap = array_type(main_f).capacity, array_type(ext_f).capacity
        main_mark = int(main_f.invalid.value) if main_f.invalid is not None else 0xFFFF
        ext_mark = int(ext_f.invalid.value) if ext_f.invalid is not None else 0
        v_unit = self.concepts[pack.field].unit
        if not self.backward:
            mul, add = factor(main_f.unit, v_unit)
            marks = [str(main_mark), str(ext_mark), str(main_mark - 1)]
            self.emit_call("_c, _p = _cells.mavlink_cells_in", [self.s(main_ref), self.s(ext_ref), *marks])
            self.emit(
                "if _p is not None:",
                f"    {self.t(pack)} = {affine('float(_p)', mul, add)}",
                "if _c is not None:",
                f"    {self.t(cells)} = tuple({affine('float(_x)', mul, add)} for _x in _c)",
            )
            return
        mul, add = factor(v_unit, main_f.unit)
        self.emit(f"_c = {self.s(cells)}", f"_p = {self.s(pack)}")
        args: list[str] = [
            f"None if _c is None else [{affine('_x', mul, add)} for _x in _c]",
            f"None if _p is None else {affine('_p', mul, add)}",
            *(str(x) for x in (main_cap, ext_cap, main_mark, ext_mark)),
            "rep",
            self.label(main_ref),
            self.label(ext_ref),
        ]
        self.emit_call(f"{self.t(main_ref)}, {self.t(ext_ref)} = _cells.mavlink_cells_out", args)

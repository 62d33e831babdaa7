"""Emitters of the ops between enumerated values and concepts: flag, flag_choice, flags, choice, value_flags.

Bits read into bool, choice or flags concepts are noted, so the function's epilogue reports the
bits of the field nothing reads as dropped; choices with no counterpart are reported too.
"""

from __future__ import annotations

from ....ir import FieldRef, Rule
from ....ir.ops import Choice, Flag, FlagChoice, Flags, ValueFlags
from ..literals import py_literal
from .context import RuleContext, constant_name

_NO_COUNTERPART = 'f"{_v!r} has no counterpart"'


class ChoiceEmitters(RuleContext):
    def note_bits(self, message: str, field: str, mask: int) -> None:
        """Bits of a source field some rule reads (the rest are reported dropped)."""
        self.bit_masks[message, field] = self.bit_masks.get((message, field), 0) | mask

    def visit_flag(self, rule: Rule, op: Flag) -> None:
        fmt, con = self.format_and_concept(rule)
        mask = self.mask(op.mask, [fmt])
        if not self.backward:
            self.note_bits(fmt.message, fmt.field, mask)
            self.emit(f"{self.t(con)} = bool({self.s(fmt)} & {py_literal(mask)})")
        else:
            target = self.t(fmt)
            self.emit(f"if {self.s(con)}:", f"    {target} |= {py_literal(mask)}")

    def visit_flag_choice(self, rule: Rule, op: FlagChoice) -> None:
        """A bit that stands for one value of a choice concept (CHARGING -> warning 'charging')."""
        fmt, con = self.format_and_concept(rule)
        mask = self.mask(op.mask, [fmt])
        value = py_literal(op.value)
        if not self.backward:
            self.note_bits(fmt.message, fmt.field, mask)
            self.emit(f"if {self.s(fmt)} & {py_literal(mask)}:", f"    {self.t(con)} = {value}")
        else:
            self.emit(f"if {self.s(con)} == {value}:", f"    {self.t(fmt)} |= {py_literal(mask)}")

    def visit_flags(self, rule: Rule, op: Flags) -> None:
        fmt, con = self.format_and_concept(rule)
        concept = self.concepts[con.field]
        table = {bit.choice: self.mask(bit.mask, [fmt]) for bit in op.map}
        ordered = tuple((c, table[c]) for c in concept.choices if c in table)
        if not self.backward:
            self.note_bits(fmt.message, fmt.field, sum(table.values()))
            bits = self.const(constant_name(con.field, "bits"), ordered)
            self.emit(f"_v = {self.s(fmt)}", f"{self.t(con)} = tuple(_n for _n, _m in {bits} if _v & _m)")
            return
        target, label = self.t(fmt), self.label(fmt)
        known = self.const(constant_name(con.field, "with", "bits"), tuple(sorted(table)))
        self.emit(f"_v = {self.s(con)}", "if _v is None:", "    if rep_u is not None:")
        self.emit_call("rep_u.unknown", [label], 2)
        self.emit("else:", f"    _b = {target}")
        for name, mask in ordered:
            self.emit(f"    if {py_literal(name)} in _v:", f"        _b |= {py_literal(mask)}")
        self.emit(f"    {target} = _b", "    if rep_d is not None:", "        for _n in _v:")
        self.emit(f"            if _n not in {known}:")
        self.emit_call("rep_d.dropped", [py_literal(f"concepts.{con.field}"), '_n + " has no counterpart"'], 4)

    def _read_value(
        self, fmt: FieldRef, con: FieldRef, by_value: dict[object, object], absent: str, unknown: object
    ) -> None:
        """A field's value looked up in ``by_value`` (``.get``'s ``absent`` default where it is not there); a
        value that is neither there nor ``unknown`` is reported dropped."""
        table = self.const(constant_name(con.field, "by", fmt.field), by_value)
        self.emit(f"_v = {self.s(fmt)}", f"{self.t(con)} = None if _v is None else {table}.get(_v{absent})")
        skip = f"({py_literal(None)}, {py_literal(unknown)})"
        self.emit(f"if rep_d is not None and _v not in {table} and _v not in {skip}:")
        self.emit_call("rep_d.dropped", [self.label(fmt), _NO_COUNTERPART], 1)

    def visit_choice(self, rule: Rule, op: Choice) -> None:
        fmt, con = self.format_and_concept(rule)
        table = [(entry.choice, self.value_of(entry.value, [fmt])) for entry in op.map]
        unknown = self.value_of(op.unknown, [fmt]) if op.unknown is not None else None
        if not self.backward:
            self._read_value(fmt, con, {v: k for k, v in table}, "", unknown)
            return
        by_choice = self.const(constant_name(fmt.field, "by", con.field), dict(table))
        target, label = self.t(fmt), self.label(fmt)
        self.emit(f"_v = {self.s(con)}", f"_w = None if _v is None else {by_choice}.get(_v)")
        self.emit("if _w is not None:", f"    {target} = _w", "else:")
        if unknown is not None:
            self.emit(f"    {target} = {py_literal(unknown)}")
        self.emit("    if rep_u is not None:")
        self.emit_call("rep_u.unknown", [label], 2)
        self.emit("    if rep_d is not None and _v is not None:")
        self.emit_call("rep_d.dropped", [py_literal(f"concepts.{con.field}"), _NO_COUNTERPART], 2)

    def visit_value_flags(self, rule: Rule, op: ValueFlags) -> None:
        """One condition at a time (UDRAL's Error) <-> a flags concept: the most severe set flag is written."""
        fmt, con = self.format_and_concept(rule)
        table = [(entry.choice, self.value_of(entry.value, [fmt])) for entry in op.map]
        none = self.value_of(op.none, [fmt]) if op.none is not None else None
        if not self.backward:
            self._read_value(fmt, con, {v: (k,) for k, v in table}, ", ()", none)
            return
        order = self.const(constant_name(fmt.field, "by", con.field), tuple(table))
        target, label = self.t(fmt), self.label(fmt)
        self.emit(f"_v = {self.s(con)}", "if _v is None:", "    if rep_u is not None:")
        self.emit_call("rep_u.unknown", [label], 2)
        self.emit("else:", f"    _w = next(((_n, _x) for _n, _x in {order} if _n in _v), (None, {py_literal(none)}))")
        self.emit(f"    {target} = _w[1]", "    if rep_d is not None:", "        for _n in _v:")
        known = self.const(constant_name(con.field, "with", fmt.field), tuple(sorted(k for k, _ in table)))
        why = f'_n + (" not written: one condition at a time" if _n in {known} else " has no counterpart")'
        self.emit("            if _n != _w[0]:")
        self.emit_call("rep_d.dropped", [py_literal(f"concepts.{con.field}"), why], 4)

"""One direction of one mapping as a function: the rules in file order, then the loss report.

:class:`FunctionBuilder` is the Python backend's :class:`~codegen.ir.mapping_visitor.OpVisitor`:
it takes its ``visit_<op>`` methods from the emitter mixins, one module per family of ops, and
mypy checks that together they cover every op. Each rule's code is preceded by a comment naming
its mapping file and line; rules reading an optional companion message (DroneCAN's
BatteryInfoAux) run only when it is given, unless the op handles its absence.
"""

from __future__ import annotations

from ....ir import CONCEPTS_ENDPOINT, Direction, FieldRef, Rule
from ....ir.mapping_values import ConstantRef
from ....ir.mapping_visitor import OpVisitor, visit
from ....ir.ops import Const
from ..literals import comment, py_literal
from .ardupilot import ArduPilotEmitters
from .cells import CellEmitters
from .choices import ChoiceEmitters
from .context import INDENT, Side, constant_name
from .devicetree import DevicetreeEmitters
from .messages import MessageEmitters
from .numeric import NumericEmitters
from .px4 import PX4Emitters
from .px4_cells import PX4CellEmitters


class FunctionBuilder(
    NumericEmitters,
    ChoiceEmitters,
    CellEmitters,
    DevicetreeEmitters,
    MessageEmitters,
    PX4Emitters,
    PX4CellEmitters,
    ArduPilotEmitters,
    OpVisitor[None],
):
    def build(self) -> list[str]:
        """The function's body lines, after the lines making the target objects."""
        for index, rule in enumerate(self.mapping.rules, 1):
            if rule.only is not None and (rule.only is Direction.BACKWARD) != self.backward:
                continue
            reads = rule.targets if self.backward else rule.sources
            optional = sorted(
                {
                    self.src.var(r.message)
                    for r in reads
                    if r.message != CONCEPTS_ENDPOINT and self.src.optional(r.message)
                }
            )
            self.rule_number = index
            self.lines += ["", *self.rule_comment(rule)]
            if optional and not rule.op.HANDLES_MISSING:
                self.lines.append(f"{INDENT}if {' and '.join(f'{v} is not None' for v in optional)}:")
                self.pad = INDENT * 2
            visit(rule, self)
            self.pad = INDENT
        self.rule_number = 0
        self.epilogue()
        return self.lines

    def rule_comment(self, rule: Rule) -> list[str]:
        """``# file.yaml:12: op from -> to``, then the rule's doc."""
        file_sources, file_targets = (self.dst, self.src) if self.backward else (self.src, self.dst)

        def spelled(refs: tuple[FieldRef, ...], side: Side) -> str:
            names = []
            for ref in refs:
                if ref.message == CONCEPTS_ENDPOINT or len(side.names) == 1:
                    names.append(ref.field or side.alias(ref.message))
                else:
                    names.append(f"{side.alias(ref.message)}.{ref.field}" if ref.field else side.alias(ref.message))
            return ", ".join(names)

        where = f"{rule.location}: " if rule.location is not None else ""
        sources = f" {spelled(rule.sources, file_sources)}" if rule.sources else ""
        if isinstance(rule.op, Const):  # the value is what a reader wants to see
            value = rule.op.value
            sources = f" {value.name if isinstance(value, ConstantRef) else py_literal(value)}"
        head = f"{where}{rule.op.NAME}{sources} -> {spelled(rule.targets, file_targets)}"
        return comment(head, INDENT) + (comment(rule.doc, INDENT) if rule.doc else [])

    def epilogue(self) -> None:
        """Loss reporting that depends on the whole function: dropped bits, source fields nobody
        read, target fields no rule wrote, and (between formats) target fields left at their marker."""
        start = len(self.lines)
        self.report_dropped()
        self.report_unknown()
        if len(self.lines) > start:
            self.lines.insert(start, "")
            self.lines.insert(start + 1, f"{INDENT}# what did not survive the conversion")

    def report_dropped(self) -> None:
        """Source bits, concepts and fields nobody read."""
        for (qualified, fname), mask in sorted(self.bit_masks.items()):
            ref = FieldRef(qualified, fname)
            var = f"{self.src.var(qualified)}.{self.attr(ref)}"
            guard = f"rep_d is not None and {var} & {py_literal(~mask)}"
            if self.src.optional(qualified):
                guard = f"{self.src.var(qualified)} is not None and {guard}"
            self.emit(f"if {guard}:", f"    _b = {var} & {py_literal(~mask)}")
            self.emit_call("rep_d.dropped", [self.label(ref), 'f"bits {_b:#x} have no counterpart"'], 1)
        if self.src.endpoint is None:
            unread = tuple(c for c in self.concepts if (CONCEPTS_ENDPOINT, c) not in self.read)
            if unread:
                names = self.const("_UNREAD_CONCEPTS", unread)
                self.emit(
                    "if rep_d is not None:",
                    f"    for _n in {names}:",
                    f"        if getattr({self.src.names[0]}, _n) is not None:",
                    '            rep_d.dropped("concepts." + _n)',
                )
        else:
            for qualified, var, alias in zip(self.src.endpoint.messages, self.src.names, self.src.aliases, strict=True):
                attrs = tuple(
                    (self.member(qualified, f.name), f.name)
                    for f in self.msg(qualified).fields
                    if not f.is_padding and (qualified, f.name) not in self.read
                )
                if not attrs:
                    continue
                names = self.const(constant_name("unread", alias, "fields"), attrs)
                default = self.const(constant_name(alias, "defaults"), None, expression=f"{self.classes[qualified]}()")
                guard = "rep_d is not None" + (f" and {var} is not None" if self.src.optional(qualified) else "")
                self.emit(
                    f"if {guard}:",
                    f"    for _a, _n in {names}:",
                    f"        if _r.differs(getattr({var}, _a), getattr({default}, _a)):",
                )
                self.emit_call("rep_d.dropped", [f"{py_literal(qualified + '.')} + _n"], 3)

    def report_unknown(self) -> None:
        """Target fields no rule wrote, and between formats those left at their marker."""
        if self.dst.endpoint is None:
            return
        pair = self.src.endpoint is not None
        for qualified, var, alias in zip(self.dst.endpoint.messages, self.dst.names, self.dst.aliases, strict=True):
            m = self.msg(qualified)
            unwritten = tuple(
                f"{qualified}.{f.name}"
                for f in m.fields
                if not f.is_padding and (qualified, f.name) not in self.written
            )
            if unwritten:
                names = self.const(constant_name("unwritten", alias, "fields"), unwritten)
                self.emit("if rep_u is not None:", f"    for _n in {names}:", "        rep_u.unknown(_n)")
            if not pair:
                continue
            for f in m.fields:
                if f.invalid is None or (qualified, f.name) not in self.written:
                    continue
                attr = f"{var}.{self.member(qualified, f.name)}"
                mark = py_literal(f.invalid.value)
                if f.invalid.first_decides:  # MAVLink [X:]: element 0 speaks for the array
                    test = f"len({attr}) > 0 and _r.is_marker({attr}[0], {mark})"
                elif f.invalid.per_element:
                    test = f"all(_r.is_marker(_x, {mark}) for _x in {attr})"
                else:
                    test = f"_r.is_marker({attr}, {mark})"
                self.emit(f"if rep_u is not None and {test}:")
                self.emit_call("rep_u.unknown", [py_literal(f"{qualified}.{f.name}")], 1)

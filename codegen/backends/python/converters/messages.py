"""Emitters of the ops on whole messages: same_names (version translation), zero_all (C ``{}``)."""

from __future__ import annotations

from ....ir import ArrayType, FieldRef, Rule, StringType
from ....ir.ops import SameNames, ZeroAll
from .context import RuleContext


class MessageEmitters(RuleContext):
    def visit_same_names(self, rule: Rule, op: SameNames) -> None:
        src_m = self.msg(rule.sources[0].message)
        dst_m = self.msg(rule.targets[0].message)
        dst_fields = {f.name: f for f in dst_m.fields}
        for f in src_m.fields:
            g = dst_fields.get(f.name)
            if f.is_padding or g is None:
                continue
            value = self.s(FieldRef(src_m.qualified_name, f.name))
            if isinstance(f.type, ArrayType):
                value = f"list({value})"
            self.emit(f"{self.t(FieldRef(dst_m.qualified_name, g.name))} = {value}")

    def visit_zero_all(self, rule: Rule, op: ZeroAll) -> None:
        for ref in rule.targets:
            m = self.msg(ref.message)
            var = self.dst.var(ref.message)
            for f in m.fields:
                if f.invalid is None or f.is_padding:
                    continue
                zero = "0.0" if self.is_float(f) else '""' if isinstance(f.type, StringType) else "0"
                if isinstance(f.type, ArrayType) and f.type.capacity is not None and not f.type.dynamic:
                    zero = f"[{zero}] * {f.type.capacity}"
                self.emit(f"{var}.{self.member(ref.message, f.name)} = {zero}")

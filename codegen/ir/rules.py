"""Cross-field rules bound to a message: the form the backends compile (pure functions, no parsing).

A :class:`~codegen.ir.CrossFieldRule` holds its expressions parsed, with loop variables resolved;
the names left are fields or constants of whichever message the rule is checked on. :func:`bind`
resolves them for one message. The rules frontend has checked at load time that every name binds
to each message the rule names; :class:`UnboundName` is for a schema assembled by other means.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import cast

from .expr import Call, Compare, Const, Expr, FieldRef, Loop, Name, Template, children, rebuild
from .fieldtypes import Range
from .messages import Message
from .schema import CrossFieldRule, Schema


class UnboundName(LookupError):
    """A name of a rule that is neither a field nor a constant of the message."""

    def __init__(self, name: Name, message: str) -> None:
        super().__init__(f"{name.text!r} is not a field or constant of {message}")
        self.name = name


@dataclass(frozen=True)
class BoundRule:
    """One rule's expressions with every name resolved against one message."""

    rule: CrossFieldRule
    where: Expr | None
    bindings: tuple[Loop, ...]  # the ``for`` loops, outermost first
    check: Expr
    path: Expr | None
    message: Template


class MessageNames:
    """What a rule's names mean in one message: its fields (padding aside) and its numeric constants."""

    def __init__(self, msg: Message) -> None:
        self.qualified_name = msg.qualified_name
        self.fields = frozenset(f.name for f in msg.fields if not f.is_padding)
        self.constants: dict[str, int | float | bool] = {}
        for c in msg.constants:
            if not isinstance(c.value, str):  # only numeric and boolean constants take part in rules
                self.constants[c.name] = c.value

    def resolve(self, name: Name) -> FieldRef | Const:
        """A field first; an unquoted name may also be a constant (loop variables are resolved at load)."""
        if name.text in self.fields:
            return FieldRef(name.text)
        if not name.quoted and name.text in self.constants:
            return Const(self.constants[name.text])
        raise UnboundName(name, self.qualified_name)

    def bind(self, expr: Expr) -> Expr:
        """``expr`` with each :class:`Name` replaced by what it means in the message."""
        if isinstance(expr, Name):
            return self.resolve(expr)
        kids = children(expr)
        return rebuild(expr, tuple(self.bind(k) for k in kids)) if kids else expr


def bind(rule: CrossFieldRule, msg: Message) -> BoundRule:
    """``rule``'s expressions bound to ``msg``; raises :class:`UnboundName` for a name it lacks."""
    names = MessageNames(msg)
    e = rule.exprs
    return BoundRule(
        rule=rule,
        where=names.bind(e.where) if e.where is not None else None,
        bindings=tuple(Loop(loop.var, names.bind(loop.iterable)) for loop in e.loops),
        check=names.bind(e.check),
        path=names.bind(e.path) if e.path is not None else None,
        message=tuple(p if isinstance(p, str) else names.bind(p) for p in e.message),
    )


def rules_for(schema: Schema, msg: Message) -> tuple[CrossFieldRule, ...]:
    """The schema's rules that apply to ``msg``, in the schema's order."""
    return tuple(r for r in schema.rules if msg.qualified_name in r.messages)


def bound_rules(schema: Schema, msg: Message) -> list[BoundRule]:
    """The schema's rules for ``msg``, bound to its fields and constants."""
    return [bind(rule, msg) for rule in rules_for(schema, msg)]


def rule_ranges(schema: Schema) -> dict[tuple[str, str], Range]:
    """The ranges that rules state of a single field: ``(message, field) -> Range`` for each error rule of the
    form ``A <= f <= B`` (or one side, ``f <= B``; with ``<`` exclusive), checked where ``f`` is known (no
    ``where``, or ``where: is_known(f)``). A converter writing the field keeps to these as to the schema's own
    range: what it writes must pass the validator."""
    out: dict[tuple[str, str], Range] = {}
    for rule in schema.rules:
        if rule.severity != "error" or rule.loops:
            continue
        for name in rule.messages:
            try:
                bound = bind(rule, schema.message(name))
            except (KeyError, UnboundName):
                continue
            found = _single_field_range(bound.check, bound.where)
            if found is not None:
                key = (name, found[0])
                out[key] = found[1].intersect(out.get(key))
    return out


def _single_field_range(check: Expr, where: Expr | None) -> tuple[str, Range] | None:
    if not isinstance(check, Compare) or not all(op in ("<", "<=") for op in check.ops):
        return None
    fields = [i for i, e in enumerate(check.operands) if isinstance(e, FieldRef)]
    if len(fields) != 1 or not all(isinstance(e, Const | FieldRef) for e in check.operands):
        return None
    at = fields[0]
    name = cast(FieldRef, check.operands[at]).name
    if where is not None and not (
        isinstance(where, Call) and where.func == "is_known" and where.args == (FieldRef(name),)
    ):
        return None
    low = check.operands[at - 1] if at > 0 else None
    high = check.operands[at + 1] if at + 1 < len(check.operands) else None
    number = (int, float)
    lo = (
        low.value
        if isinstance(low, Const) and isinstance(low.value, number) and not isinstance(low.value, bool)
        else None
    )
    hi = (
        high.value
        if isinstance(high, Const) and isinstance(high.value, number) and not isinstance(high.value, bool)
        else None
    )
    if lo is None and hi is None:
        return None
    return name, Range(
        lo, hi, at > 0 and check.ops[at - 1] == "<", at + 1 < len(check.operands) and check.ops[at] == "<"
    )

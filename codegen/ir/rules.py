"""Cross-field rules bound to a message: the form the backends compile (pure functions, no parsing).

A :class:`~codegen.ir.CrossFieldRule` holds its expressions parsed, with loop variables resolved;
the names left are fields or constants of whichever message the rule is checked on. :func:`bind`
resolves them for one message. The rules frontend has checked at load time that every name binds
to each message the rule names; :class:`UnboundName` is for a schema assembled by other means.
"""

from __future__ import annotations

from dataclasses import dataclass

from .expr import Const, Expr, FieldRef, Loop, Name, Template, children, rebuild
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

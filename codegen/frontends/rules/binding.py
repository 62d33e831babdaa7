"""What the names of a rule mean: loop variables, resolved when the rule is loaded, and fields or
constants of each message the rule names, checked once the messages are loaded.

The meaning itself is the IR's (:class:`codegen.ir.rules.MessageNames`), so the backends bind
exactly what was checked here; this module turns every problem into a :class:`SchemaError` naming
the rule file's line.
"""

from __future__ import annotations

from ...errors import SchemaError
from ...ir import CrossFieldRule, Message
from ...ir.expr import Call, Expr, Loop, Name, Quant, RuleExpressions, VarRef, children, is_place, rebuild
from ...ir.rules import MessageNames, UnboundName


def scoped(exprs: RuleExpressions) -> RuleExpressions:
    """``exprs`` with loop variables resolved to :class:`VarRef`: a ``for`` variable is in scope in
    the later loops, the assert, the path and the message; a generator's variable in its body."""
    scope: frozenset[str] = frozenset()
    loops: list[Loop] = []
    for loop in exprs.loops:
        loops.append(Loop(loop.var, _scoped(loop.iterable, scope)))
        scope = scope | {loop.var}
    return RuleExpressions(
        check=_scoped(exprs.check, scope),
        where=_scoped(exprs.where, frozenset()) if exprs.where is not None else None,
        loops=tuple(loops),
        path=_scoped(exprs.path, scope) if exprs.path is not None else None,
        message=tuple(p if isinstance(p, str) else _scoped(p, scope) for p in exprs.message),
    )


def _scoped(expr: Expr, scope: frozenset[str]) -> Expr:
    if isinstance(expr, Name):
        # a backquoted name is always a field of the message
        return VarRef(expr.text) if not expr.quoted and expr.text in scope else expr
    if isinstance(expr, Quant):
        return Quant(expr.func, _scoped(expr.body, scope | {expr.var}), expr.var, _scoped(expr.iterable, scope))
    kids = children(expr)
    return rebuild(expr, tuple(_scoped(k, scope) for k in kids)) if kids else expr


class _Checker:
    def __init__(self, rule: CrossFieldRule, msg: Message) -> None:
        self.rule = rule
        self.msg = msg
        self.names = MessageNames(msg)
        self.lines = dict(rule.lines)

    def fail(self, key: str, text: str) -> SchemaError:
        line = self.lines.get(key, self.rule.location.line)
        return SchemaError(self.rule.location.file, line, f"rule {self.rule.id!r}: {text}")

    def expr(self, expr: Expr, key: str) -> None:
        """Every name of ``expr`` binds, and ``is_known()`` is given a field; the first problem in
        source order (a call's arguments before the call) is reported."""
        for child in children(expr):
            self.expr(child, key)
        if isinstance(expr, Name):
            try:
                self.names.resolve(expr)
            except UnboundName:
                raise self.fail(
                    key,
                    f"{expr.text!r} (column {expr.column} of '{key}') is not a field, constant or "
                    f"loop variable of {self.msg.qualified_name}",
                ) from None
        elif isinstance(expr, Call) and expr.func == "is_known":
            arg = expr.args[0]
            if not (isinstance(arg, Name) and arg.text in self.names.fields):
                raise self.fail(key, f"is_known() takes a field name (column {expr.column} of '{key}')")

    def rule_binds(self) -> None:
        exprs = self.rule.exprs
        if exprs.where is not None:
            self.expr(exprs.where, "where")
        seen: set[str] = set()
        for loop in exprs.loops:
            if loop.var in seen or loop.var in self.names.fields:
                raise self.fail(
                    "for", f"loop variable {loop.var!r} hides a field or another loop variable; pick another name"
                )
            self.expr(loop.iterable, "for")
            seen.add(loop.var)
        self.expr(exprs.check, "assert")
        if exprs.path is not None:
            self.expr(exprs.path, "path")
            if not is_place(self.names.bind(exprs.path)):
                raise self.fail("path", "expected 'path' to name a field or loop variable, optionally indexed")
        for part in exprs.message:
            if not isinstance(part, str):
                self.expr(part, "message")


def check_binding(rule: CrossFieldRule, msg: Message) -> None:
    """``rule`` binds to ``msg``: its names are fields, constants or loop variables, its loops hide
    no field, ``is_known()`` reads a field and ``path`` names a place; else a :class:`SchemaError`."""
    _Checker(rule, msg).rule_binds()

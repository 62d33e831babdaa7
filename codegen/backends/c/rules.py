"""Cross-field rules (``Schema.rules`` bound to a message) as C statements of the message's validator,
after its field checks, as ``codegen/backends/python/validators/rules.py`` compiles them into Python:
the rule's ``where`` guard, its ``for i in range(a, b)`` loops (kept to the message's largest array,
as the Python ``_v.span``), its check, and a problem (the rule's id, the field its ``path`` names, the
element) when the check fails. Values are read as Python compares them: integers in int64_t, floats in
double. A rule using what C does not spell here (text, ``in``, ``all``/``any``, floor division) is
left out of the C validator; :func:`c_rules` says which."""

from __future__ import annotations

from ...ir import ArrayType, Field, Message, PrimitiveKind, PrimitiveType, Schema
from ...ir.expr import Binary, BoolOp, Call, Compare, Const, Expr, FieldRef, Index, Not, Unary, VarRef
from ...ir.rules import BoundRule, bound_rules
from .convert_values import Unsupported, f64_literal, literal
from .types import ident

_OPS = {"<", "<=", ">", ">=", "==", "!="}


class _Rule:
    def __init__(self, msg: Message) -> None:
        self.msg = msg
        self.fields = {f.name: f for f in msg.fields if not f.is_padding}
        caps = [f.type.capacity or 0 for f in msg.fields if isinstance(f.type, ArrayType)]
        self.limit = max(caps, default=0)

    def field(self, name: str) -> tuple[Field, PrimitiveType]:
        f = self.fields[name]
        t = f.type
        while isinstance(t, ArrayType):
            t = t.element
        if not isinstance(t, PrimitiveType) or t.kind is PrimitiveKind.CHAR:
            raise Unsupported(f"{name}: not a number")
        return f, t

    def value(self, name: str, at: str = "") -> str:
        _, t = self.field(name)
        cast = "double" if t.kind is PrimitiveKind.FLOAT else "int64_t"
        return f"(({cast})m->{ident(name)}{at})"

    def expr(self, e: Expr) -> str:
        if isinstance(e, Const):
            if isinstance(e.value, bool):
                return "1" if e.value else "0"
            if isinstance(e.value, int):
                return f"{e.value}LL"
            if isinstance(e.value, float):
                return f64_literal(e.value)
            raise Unsupported("text")
        if isinstance(e, FieldRef):
            if isinstance(self.fields[e.name].type, ArrayType):
                raise Unsupported(f"{e.name}: a whole array")
            return self.value(e.name)
        if isinstance(e, VarRef):
            return f"v_{e.name}"
        if isinstance(e, Unary):
            return f"({e.op}{self.expr(e.operand)})"
        if isinstance(e, Binary):
            if e.op not in ("+", "-", "*", "/"):
                raise Unsupported(f"the operator {e.op}")
            left, right = self.expr(e.left), self.expr(e.right)
            if e.op == "/":  # Python's true division
                return f"((double){left} / (double){right})"
            return f"({left} {e.op} {right})"
        if isinstance(e, Compare):
            if any(op not in _OPS for op in e.ops):
                raise Unsupported("membership")
            terms = [self.expr(x) for x in e.operands]
            return (
                "(" + " && ".join(f"{a} {op} {b}" for a, op, b in zip(terms[:-1], e.ops, terms[1:], strict=True)) + ")"
            )
        if isinstance(e, BoolOp):
            return "(" + (" && " if e.op == "and" else " || ").join(self.expr(v) for v in e.values) + ")"
        if isinstance(e, Not):
            return f"(!{self.expr(e.operand)})"
        if isinstance(e, Index):
            if not isinstance(e.target, FieldRef):
                raise Unsupported("an index into an expression")
            f, _ = self.field(e.target.name)
            assert isinstance(f.type, ArrayType)
            return self.value(e.target.name, f"[{self.expr(e.index)}]")
        if isinstance(e, Call):
            return self.call(e)
        raise Unsupported(type(e).__name__)

    def length(self, f: Field) -> str:
        t = f.type
        assert isinstance(t, ArrayType)
        return f"((int64_t)m->{ident(f.name)}_len)" if t.dynamic else f"{t.capacity or 0}LL"

    def call(self, e: Call) -> str:
        if e.func == "len" and isinstance(e.args[0], FieldRef):
            f = self.fields[e.args[0].name]
            if not isinstance(f.type, ArrayType):
                raise Unsupported("len of a scalar")
            return self.length(f)
        if e.func == "is_known" and isinstance(e.args[0], FieldRef):
            return self.known(e.args[0].name)
        raise Unsupported(f"{e.func}()")

    def known(self, name: str) -> str:
        """The Python ``known_expr``: the field is not at its "unknown" sentinel."""
        f, t = self.field(name)
        s = f.invalid
        if s is None:
            return "1"
        v = f"m->{ident(name)}"

        def differs(x: str) -> str:
            if s.is_nan:
                return f"!battgen_f{64 if t.bits > 32 else 32}_is_nan({x})"
            return f"{x} != {literal(t, s.value)}"

        if not isinstance(f.type, ArrayType):
            return f"({differs(v)})"
        if s.elements:
            raise Unsupported("per-position markers")
        if s.first_decides:
            return f"({self.length(f)} > 0 && {differs(v + '[0]')})"
        raise Unsupported("is_known of an array")


def rule_lines(schema: Schema, msg: Message) -> tuple[list[str], int, list[str]]:
    """(statements over ``m``, ``out``, ``cap``, ``n``; how many problems they can report at most;
    the rules left out, with why)."""
    lines: list[str] = []
    most = 0
    left: list[str] = []
    for bound in bound_rules(schema, msg):
        try:
            body, count = _one(_Rule(msg), bound)
        except Unsupported as why:
            left.append(f"{bound.rule.id} ({msg.qualified_name}): {why}")
            continue
        lines += [f"/* rule {bound.rule.id} ({bound.rule.location}) */", "{", *body, "}"]
        most += count
    return lines, most, left


def _one(r: _Rule, bound: BoundRule) -> tuple[list[str], int]:
    body: list[str] = []
    if len(bound.bindings) > 1:
        raise Unsupported("nested loops")
    place = bound.path
    index = "-1"
    while isinstance(place, Index):
        if index != "-1":
            raise Unsupported("a path with two indexes")
        index = f"(int32_t){r.expr(place.index)}"
        place = place.target
    if not isinstance(place, FieldRef):
        raise Unsupported("a path that is not a field")
    report = f'battgen_report_check(out, cap, &n, "{place.name}", {index}, "cross-field:{bound.rule.id}");'
    check = [f"if (!{r.expr(bound.check)}) {{ {report} }}"]
    count = 1
    for var, iterable in bound.bindings:
        if not (isinstance(iterable, Call) and iterable.func == "range" and len(iterable.args) in (1, 2)):
            raise Unsupported("a loop not over range()")
        args = [r.expr(a) for a in iterable.args]
        start, stop = ("0LL", args[0]) if len(args) == 1 else args
        body += [f"int64_t v_{var}, lo = {start}, hi = {stop};"]
        body += ["if (lo < 0) { lo = 0; }", f"if (hi > {r.limit}LL) {{ hi = {r.limit}LL; }}"]
        check = [f"for (v_{var} = lo; v_{var} < hi; v_{var}++) {{", *check, "}"]
        count = r.limit
    if bound.where is not None:
        check = [f"if ({r.expr(bound.where)}) {{", *check, "}"]
    return body + check, count

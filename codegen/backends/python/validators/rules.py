"""Cross-field rules (``Schema.rules``, bound to a message by :mod:`codegen.ir.rules`) compiled into
statements of the generated ``validate()``.

Expressions become plain Python over locals: fields are read once into ``r_<name>``, loop
variables are ``v_<name>``, constants are literals. Nothing of a rule file reaches the output but
through these node types and :func:`~.literals.py_literal`, so a rule cannot inject code.
"""

from __future__ import annotations

from ....ir import ArrayType, Field, FieldType, Message, Sentinel, StringType
from ....ir.expr import (
    Binary,
    BoolOp,
    Call,
    Compare,
    Const,
    Expr,
    FieldRef,
    Index,
    ListLit,
    Name,
    Not,
    Quant,
    Unary,
    VarRef,
    referenced_fields,
)
from ....ir.rules import BoundRule
from ..literals import py_literal


def known_expr(f: Field, value: str, optional: bool) -> str:
    """True when ``value`` (the field's value) is not its "unknown" sentinel."""
    if f.pattern is not None:
        return f"bool({value})"
    s = f.invalid
    parts = [f"{value} is not None"] if optional else []
    if s is not None:
        if isinstance(f.type, StringType):  # a char array marked [0]: the empty text is unknown
            parts.append(f"{value} != {py_literal(chr(int(s.value)) * (f.type.capacity or 1) if s.value else '')}")
        elif isinstance(f.type, ArrayType) and s.elements:
            parts.append(_known_by_position(f.type, s, value))
        elif isinstance(f.type, ArrayType) and s.first_decides:  # [X:]: the first element speaks for all
            first = f"{value}[0] == {value}[0]" if s.is_nan else f"{value}[0] != {py_literal(s.value)}"
            parts.append(f"(len({value}) > 0 and {first})")
        elif isinstance(f.type, ArrayType):
            test = "e == e" if s.is_nan else f"e != {py_literal(s.value)}"
            parts.append(f"any({test} for e in {value})")
        else:
            parts.append(f"{value} == {value}" if s.is_nan else f"{value} != {py_literal(s.value)}")
    return " and ".join(parts) if parts else "True"


def _known_by_position(t: ArrayType, s: Sentinel, value: str) -> str:
    """Known unless every element carries its position's marker (an element without one is always known)."""
    markers = s.elements
    if None in markers or (not t.dynamic and t.capacity is not None and len(markers) < t.capacity):
        return "True"
    tests = [
        f"{value}[{i}] == {value}[{i}]" if isinstance(m, float) and m != m else f"{value}[{i}] != {py_literal(m)}"
        for i, m in enumerate(markers)
    ]
    return f"(len({value}) != {len(markers)} or " + " or ".join(tests) + ")"


_NEGATED_MEMBERSHIP = {"in": "not in", "not in": "in"}

# The bound of a rule's range() over unbounded arrays; the same figure as the runtime's _validate.SPAN_LIMIT.
SPAN_LIMIT = 1 << 16


def _capacity(t: FieldType) -> int | None:
    """The most elements any array level of ``t`` holds (None: unbounded)."""
    if not isinstance(t, ArrayType):
        return 0
    inner = _capacity(t.element)
    if t.capacity is None or inner is None:
        return None
    return max(t.capacity, inner)


class _Emitter:
    def __init__(self, msg: Message, idents: dict[str, str]) -> None:
        self.msg = msg
        self.idents = idents  # schema name -> attribute
        self.fields = {f.name: f for f in msg.fields}
        self.optional = msg.devicetree is not None

    def span_limit(self) -> int:
        """How many indices a rule's range() may cover: the largest array capacity of the message, or
        the runtime's SPAN_LIMIT when an array of the message is unbounded (devicetree tables)."""
        caps = [_capacity(f.type) for f in self.msg.fields if isinstance(f.type, ArrayType)]
        known = [c for c in caps if c is not None]
        return max(known) if known and len(known) == len(caps) else SPAN_LIMIT

    def local(self, name: str) -> str:
        return "r_" + self.idents[name]

    def expr(self, e: Expr) -> str:
        if isinstance(e, Const):
            return py_literal(e.value)
        if isinstance(e, FieldRef):
            return self.local(e.name)
        if isinstance(e, VarRef):
            return "v_" + e.name
        if isinstance(e, Unary):
            return f"({e.op}{self.expr(e.operand)})"
        if isinstance(e, Binary):
            return f"({self.expr(e.left)} {e.op} {self.expr(e.right)})"
        if isinstance(e, Compare):
            out = [self.expr(e.operands[0])]
            for op, operand in zip(e.ops, e.operands[1:], strict=True):
                out += [op, self.expr(operand)]
            return "(" + " ".join(out) + ")"
        if isinstance(e, BoolOp):
            return "(" + f" {e.op} ".join(self.expr(v) for v in e.values) + ")"
        if isinstance(e, Not):
            return f"(not {self.expr(e.operand)})"
        if isinstance(e, Index):
            return f"{self.expr(e.target)}[{self.expr(e.index)}]"
        if isinstance(e, ListLit):
            return "[" + ", ".join(self.expr(i) for i in e.items) + "]"
        if isinstance(e, Quant):
            return f"{e.func}({self.expr(e.body)} for v_{e.var} in {self.expr(e.iterable)})"
        if isinstance(e, Call):
            return self.call(e)
        assert not isinstance(e, Name), "names are resolved before emission"
        raise AssertionError(e)

    def failed(self, e: Expr) -> str:
        """The condition under which check ``e`` fails: ``not (check)``, spelled ``a not in b`` for a
        single membership test as Python style asks (the same test, E713)."""
        if isinstance(e, Compare) and len(e.ops) == 1 and e.ops[0] in _NEGATED_MEMBERSHIP:
            left, right = (self.expr(o) for o in e.operands)
            return f"({left} {_NEGATED_MEMBERSHIP[e.ops[0]]} {right})"
        return f"not {self.expr(e)}"

    def call(self, e: Call) -> str:
        args = [self.expr(a) for a in e.args]
        if e.func == "is_known":
            target = e.args[0]
            assert isinstance(target, FieldRef)
            f = self.fields[target.name]
            return "(" + known_expr(f, self.local(f.name), self.optional and f.pattern is None) + ")"
        if e.func == "reversed":
            return f"list(reversed({args[0]}))"
        if e.func == "keys":
            return f"sorted({args[0]}.keys())"
        if e.func == "range":
            # a rule's range() indexes arrays: clamped to the schema's capacity, so a corrupt count in a
            # record (cell_count = -10**8) cannot make validate() loop for minutes
            return f"_v.span({', '.join(args)}, limit={self.span_limit()})"
        return f"{e.func}({', '.join(args)})"


def _place_path(e: Expr, em: _Emitter, paths: dict[str, str | None]) -> str | None:
    indexes: list[Expr] = []
    while isinstance(e, Index):
        indexes.insert(0, e.index)
        e = e.target
    if isinstance(e, FieldRef):
        base: str | None = py_literal(e.name)
    elif isinstance(e, VarRef):
        base = paths.get(e.name)
    else:
        base = None
    if base is None:
        return None
    for ix in indexes:
        base += f" + '[' + str({em.expr(ix)}) + ']'"
    return base


def rule_lines(bound: BoundRule, msg: Message, idents: dict[str, str]) -> tuple[list[str], set[str]]:
    """Statements checking one rule, and the local names they use (declared Any by the caller)."""
    em = _Emitter(msg, idents)
    rule = bound.rule
    exprs: list[Expr | None] = [bound.where, *(it for _, it in bound.bindings), bound.check, bound.path]
    exprs += [p for p in bound.message if not isinstance(p, str)]
    every = {f.name: f for f in msg.fields}
    used: dict[str, None] = {}
    guarded: dict[str, None] = {}
    for e in exprs:
        used.update(dict.fromkeys(referenced_fields(e, skip_is_known=False)))
        guarded.update(dict.fromkeys(referenced_fields(e)))
    names: set[str] = {"r_" + idents[n] for n in used}
    lines = [f"# rule {rule.id} ({rule.location})"]
    body: list[str] = [f"r_{idents[n]} = self.{idents[n]}" for n in used]
    ind = ""
    checks: list[str] = []
    if em.optional:
        checks += [f"r_{idents[n]} is not None" for n in guarded if every[n].pattern is None]
    if bound.where is not None:
        checks.append(em.expr(bound.where))
    if checks:
        body.append("if " + " and ".join(checks) + ":")
        ind += "    "
    paths: dict[str, str | None] = {}
    innermost: str | None = None
    for n, (var, iterable) in enumerate(bound.bindings):
        names.add("v_" + var)
        it = em.expr(iterable)
        parent = _place_path(iterable, em, paths)
        if isinstance(iterable, FieldRef) and every[iterable.name].pattern is not None:
            names.add(f"k_{n}")
            body.append(f"{ind}for k_{n}, v_{var} in _v.entries({it}):")
            paths[var] = f"k_{n}"
        elif parent is not None:
            names.add(f"i_{n}")
            body.append(f"{ind}for i_{n}, v_{var} in enumerate({it}):")
            paths[var] = f"{parent} + '[' + str(i_{n}) + ']'"
        else:
            body.append(f"{ind}for v_{var} in {it}:")
            paths[var] = None
        if paths[var] is not None:
            innermost = var
        ind += "    "
    if bound.path is not None and (where := _place_path(bound.path, em, paths)) is not None:
        path_code, value_code = where, em.expr(bound.path)
    elif innermost is not None:
        path_code, value_code = paths[innermost] or "''", "v_" + innermost
    else:
        first = referenced_fields(bound.check) or list(used)
        path_code = py_literal(first[0]) if first else py_literal(rule.id)
        value_code = f"r_{idents[first[0]]}" if first else "None"
    message = " + ".join(py_literal(p) if isinstance(p, str) else f"_v.fmt({em.expr(p)})" for p in bound.message)
    report = (
        f"out.append(_v.rule({path_code}, {py_literal(rule.id)}, {value_code}, {py_literal(rule.check)}, "
        f"{message or py_literal(rule.id)}, {py_literal(rule.severity)}))"
    )
    if bound.bindings:
        body += [
            f"{ind}try:",
            f"{ind}    if {em.failed(bound.check)}:",
            f"{ind}        {report}",
            f"{ind}except _v.SLOW:",
            f"{ind}    pass",
        ]
    else:
        body += [f"{ind}if {em.failed(bound.check)}:", f"{ind}    {report}"]
    lines += ["try:", *["    " + b for b in body], "except _v.SLOW:", "    pass  # the field checks report the cause"]
    return lines, names

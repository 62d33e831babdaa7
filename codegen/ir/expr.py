"""Cross-field rule expressions as the IR holds them: an AST of frozen nodes, and pure helpers on it.

The rules frontend (:mod:`codegen.frontends.rules`) parses the text of a rule file into these nodes
once; the backends only walk them. The language is deliberately small -- no attribute access, no
assignment, no calls but :data:`FUNCTIONS` -- so a rule file can never run code of its author's choosing.

A name goes through three stages. The parser writes every name as a :class:`Name`; the frontend
turns the names bound by a rule's ``for`` loops or by ``all``/``any`` generators into
:class:`VarRef` when it loads the rule (that depends on the rule alone); the names left are fields
or constants of a message, and :func:`codegen.ir.rules.bind` resolves them to :class:`FieldRef`
or :class:`Const` for each message the rule applies to.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

# The functions a rule may call: name -> (minimum, maximum) number of arguments (None: any number).
# A backend must implement each with Python's meaning, except ``is_known(field)`` (the field does
# not hold its "unknown" sentinel), ``keys(mapping)`` (sorted keys) and ``reversed`` (a list).
FUNCTIONS: dict[str, tuple[int, int | None]] = {
    "len": (1, 1),
    "abs": (1, 1),
    "min": (1, None),
    "max": (1, None),
    "sum": (1, 1),
    "sorted": (1, 1),
    "reversed": (1, 1),
    "is_known": (1, 1),
    "range": (1, 2),
    "str": (1, 1),
    "keys": (1, 1),
    "all": (1, 1),
    "any": (1, 1),
}


@dataclass(frozen=True)
class Const:
    value: int | float | str | bool


@dataclass(frozen=True)
class Name:
    """A field or constant of the message, as written; ``quoted`` when it was in backquotes
    (then it can only be a field); ``column`` (1-based) places it in the expression's text."""

    text: str
    quoted: bool
    column: int


@dataclass(frozen=True)
class FieldRef:
    """A field of the message, by its schema name (after binding)."""

    name: str


@dataclass(frozen=True)
class VarRef:
    """A loop variable of the rule's ``for`` or of an enclosing ``all``/``any`` generator."""

    name: str


@dataclass(frozen=True)
class Unary:
    op: str  # "-" / "+"
    operand: Expr


@dataclass(frozen=True)
class Binary:
    op: str  # "+", "-", "*", "/", "//", "%"
    left: Expr
    right: Expr


@dataclass(frozen=True)
class Compare:
    """A comparison chain, as in Python: ``a < b <= c`` is ``a < b and b <= c``."""

    ops: tuple[str, ...]  # "<", "<=", ">", ">=", "==", "!=", "in", "not in"
    operands: tuple[Expr, ...]


@dataclass(frozen=True)
class BoolOp:
    op: str  # "and" / "or"
    values: tuple[Expr, ...]


@dataclass(frozen=True)
class Not:
    operand: Expr


@dataclass(frozen=True)
class Index:
    target: Expr
    index: Expr


@dataclass(frozen=True)
class Call:
    func: str  # a key of FUNCTIONS, called with an allowed number of arguments
    args: tuple[Expr, ...]
    column: int


@dataclass(frozen=True)
class Quant:
    """``all(body for var in iterable)`` / ``any(...)``; ``var`` is in scope in ``body`` only."""

    func: str  # "all" / "any"
    body: Expr
    var: str
    iterable: Expr


@dataclass(frozen=True)
class ListLit:
    items: tuple[Expr, ...]


Expr = Const | Name | FieldRef | VarRef | Unary | Binary | Compare | BoolOp | Not | Index | Call | Quant | ListLit

# A message template: literal text and ``{expr}`` placeholders, in order.
Template = tuple[str | Expr, ...]


class Loop(NamedTuple):
    """One ``for`` clause of a rule: ``var in iterable``."""

    var: str
    iterable: Expr


@dataclass(frozen=True)
class RuleExpressions:
    """The parsed expressions of one rule (the keys of its entry in the rule file)."""

    check: Expr  # ``assert``
    where: Expr | None = None
    loops: tuple[Loop, ...] = ()  # ``for``, outermost first
    path: Expr | None = None
    message: Template = ()


def children(expr: Expr) -> tuple[Expr, ...]:
    """The direct sub-expressions of ``expr``, in source order (a generator's body before its iterable)."""
    if isinstance(expr, Unary | Not):
        return (expr.operand,)
    if isinstance(expr, Binary):
        return (expr.left, expr.right)
    if isinstance(expr, Compare):
        return expr.operands
    if isinstance(expr, BoolOp):
        return expr.values
    if isinstance(expr, Index):
        return (expr.target, expr.index)
    if isinstance(expr, ListLit):
        return expr.items
    if isinstance(expr, Quant):
        return (expr.body, expr.iterable)
    if isinstance(expr, Call):
        return expr.args
    return ()


def rebuild(expr: Expr, kids: tuple[Expr, ...]) -> Expr:
    """``expr`` with its sub-expressions replaced by ``kids`` (as many, in the order of :func:`children`)."""
    if isinstance(expr, Unary):
        return Unary(expr.op, kids[0])
    if isinstance(expr, Not):
        return Not(kids[0])
    if isinstance(expr, Binary):
        return Binary(expr.op, kids[0], kids[1])
    if isinstance(expr, Compare):
        return Compare(expr.ops, kids)
    if isinstance(expr, BoolOp):
        return BoolOp(expr.op, kids)
    if isinstance(expr, Index):
        return Index(kids[0], kids[1])
    if isinstance(expr, ListLit):
        return ListLit(kids)
    if isinstance(expr, Quant):
        return Quant(expr.func, kids[0], expr.var, kids[1])
    if isinstance(expr, Call):
        return Call(expr.func, kids, expr.column)
    return expr


def referenced_fields(expr: Expr | None, *, skip_is_known: bool = True) -> list[str]:
    """Schema names of the fields a bound ``expr`` reads, in first-use order; with ``skip_is_known``
    the argument of ``is_known()`` does not count (it reads the field's sentinel, not its value)."""
    out: dict[str, None] = {}

    def walk(e: Expr) -> None:
        if isinstance(e, FieldRef):
            out[e.name] = None
        elif not (skip_is_known and isinstance(e, Call) and e.func == "is_known"):
            for child in children(e):
                walk(child)

    if expr is not None:
        walk(expr)
    return list(out)


def is_place(expr: Expr) -> bool:
    """True when ``expr`` names somewhere a violation can be reported: a field or loop variable, optionally indexed."""
    while isinstance(expr, Index):
        expr = expr.target
    return isinstance(expr, FieldRef | VarRef)

"""Expressions built from operators: binary, boolean and comparison chains, unary operators,
conditional expressions, lambdas, ``:=`` and comprehensions, as ruff lays them out.

A chain of operators is flattened (parenthesised operands stay whole) and breaks before each
operator of its lowest precedence; the runs between them break the same way on their own.
"""

from __future__ import annotations

import ast
import enum

from . import document as d
from .context import LayoutContext, Needs, Parens
from .document import Element, Line


class Precedence(enum.IntEnum):
    """Operator precedence, binding tightest first: chains break at the highest value first."""

    NONE = 0
    ATTRIBUTE = 1
    EXPONENTIAL = 2
    BITWISE_INVERSION = 3
    MULTIPLICATIVE = 4
    ADDITIVE = 5
    SHIFT = 6
    BITWISE_AND = 7
    BITWISE_XOR = 8
    BITWISE_OR = 9
    COMPARATOR = 10
    BOOLEAN = 11
    CONDITIONAL = 12


BINARY: dict[type[ast.operator], tuple[str, Precedence]] = {
    ast.Add: ("+", Precedence.ADDITIVE),
    ast.Sub: ("-", Precedence.ADDITIVE),
    ast.Mult: ("*", Precedence.MULTIPLICATIVE),
    ast.MatMult: ("@", Precedence.MULTIPLICATIVE),
    ast.Div: ("/", Precedence.MULTIPLICATIVE),
    ast.FloorDiv: ("//", Precedence.MULTIPLICATIVE),
    ast.Mod: ("%", Precedence.MULTIPLICATIVE),
    ast.Pow: ("**", Precedence.EXPONENTIAL),
    ast.LShift: ("<<", Precedence.SHIFT),
    ast.RShift: (">>", Precedence.SHIFT),
    ast.BitAnd: ("&", Precedence.BITWISE_AND),
    ast.BitXor: ("^", Precedence.BITWISE_XOR),
    ast.BitOr: ("|", Precedence.BITWISE_OR),
}
_COMPARE: dict[type[ast.cmpop], str] = {
    ast.Eq: "==",
    ast.NotEq: "!=",
    ast.Lt: "<",
    ast.LtE: "<=",
    ast.Gt: ">",
    ast.GtE: ">=",
    ast.Is: "is",
    ast.IsNot: "is not",
    ast.In: "in",
    ast.NotIn: "not in",
}
_UNARY: dict[type[ast.unaryop], str] = {ast.Invert: "~", ast.Not: "not", ast.UAdd: "+", ast.USub: "-"}

Operator = tuple[str, Precedence]
Part = ast.expr | Operator


class OperatorLayout(LayoutContext):
    # -- operator chains -------------------------------------------------------------------------

    def fmt_BinOp(self, node: ast.BinOp) -> list[Element]:
        return self.chain(node)

    def fmt_BoolOp(self, node: ast.BoolOp) -> list[Element]:
        return self.chain(node)

    def fmt_Compare(self, node: ast.Compare) -> list[Element]:
        return self.chain(node)

    def flatten(self, node: ast.expr, parts: list[Part], *, root: bool = False) -> None:
        """Operands and operators of nested chains written without parentheses, left to right."""
        if not root and self.source.is_parenthesized(node):
            parts.append(node)
        elif isinstance(node, ast.BinOp):
            self.flatten(node.left, parts)
            parts.append(BINARY[type(node.op)])
            self.flatten(node.right, parts)
        elif isinstance(node, ast.BoolOp):
            word = "and" if isinstance(node.op, ast.And) else "or"
            for i, value in enumerate(node.values):
                if i:
                    parts.append((word, Precedence.BOOLEAN))
                self.flatten(value, parts)
        elif isinstance(node, ast.Compare):
            self.flatten(node.left, parts)
            for op, operand in zip(node.ops, node.comparators, strict=True):
                parts.append((_COMPARE[type(op)], Precedence.COMPARATOR))
                self.flatten(operand, parts)
        else:
            parts.append(node)

    def chain(self, node: ast.BinOp | ast.BoolOp | ast.Compare) -> list[Element]:
        parts: list[Part] = []
        self.flatten(node, parts, root=True)
        for part in parts:
            if isinstance(part, ast.Constant) and isinstance(part.value, str | bytes):
                if len(self.source.string_parts(part)) > 1 and not self.source.is_parenthesized(part):
                    raise NotImplementedError("implicitly concatenated string in an operator chain")
            if isinstance(part, tuple) and part[0] == "**":
                raise NotImplementedError("power operator")
        return self.in_parens_only_group(self.chain_slice(parts))

    def chain_slice(self, parts: list[Part]) -> list[Element]:
        if len(parts) == 1:
            return self.operand(parts[0])
        lowest = max(p[1] for p in parts[1::2] if isinstance(p, tuple))
        out: list[Element] = []
        start = 0
        for i in range(1, len(parts), 2):
            operator = parts[i]
            assert isinstance(operator, tuple)
            if operator[1] != lowest:
                continue
            left = parts[start:i]
            out += self.operand(left[0]) if len(left) == 1 else self.in_parens_only_group(self.chain_slice(left))
            out += [*self.in_parens_only_line(), operator[0], " "]
            start = i + 1
        right = parts[start:]
        out += self.operand(right[0]) if len(right) == 1 else self.in_parens_only_group(self.chain_slice(right))
        return out

    def operand(self, part: Part) -> list[Element]:
        assert not isinstance(part, tuple)
        return self.expr(part, Parens.ALWAYS if self.source.is_parenthesized(part) else Parens.NEVER)

    # -- other operators -----------------------------------------------------------------------------

    def fmt_UnaryOp(self, node: ast.UnaryOp) -> list[Element]:
        out: list[Element] = [_UNARY[type(node.op)]]
        if isinstance(node.op, ast.Not):
            out.append(" ")
        operand = node.operand
        power = isinstance(operand, ast.BinOp) and isinstance(operand.op, ast.Pow)
        return out + self.expr(operand, Parens.ALWAYS if power else Parens.PRESERVE)

    def fmt_IfExp(self, node: ast.IfExp) -> list[Element]:
        return self.if_expression(node, nested=False)

    def if_expression(self, node: ast.IfExp, *, nested: bool) -> list[Element]:
        out = [*self.expr(node.body), *self.in_parens_only_line(), "if", " ", *self.expr(node.test)]
        out += [*self.in_parens_only_line(), "else", " "]
        orelse = node.orelse
        if isinstance(orelse, ast.IfExp) and not self.source.is_parenthesized(orelse):
            out += self.if_expression(orelse, nested=True)  # a chain of else-ifs breaks as one
        else:
            out += self.in_parens_only_group(self.expr(orelse))
        return out if nested else self.in_parens_only_group(out)

    def fmt_NamedExpr(self, node: ast.NamedExpr) -> list[Element]:
        target = d.group(self.expr(node.target), self.in_parens_only_line())
        return [*target, ":=", " ", *self.expr(node.value)]

    def fmt_Lambda(self, node: ast.Lambda) -> list[Element]:
        params = node.args
        if params.posonlyargs or params.vararg or params.kwonlyargs or params.kwarg or params.defaults:
            raise NotImplementedError("lambda with more than plain parameters")
        out: list[Element] = ["lambda"]
        if params.args:
            out += [" ", ", ".join(a.arg for a in params.args)]
        out += [":", " "]
        body = node.body
        needs = self.needs_parentheses(body, node)
        if needs is Needs.ALWAYS:
            return out + self.expr(body, Parens.ALWAYS)
        if needs is Needs.MULTILINE:
            return out + self.parenthesize_if_expands(lambda: self.expr(body, Parens.NEVER))
        if isinstance(body, ast.Call | ast.Subscript):
            flat = self.expr(body, Parens.NEVER)
            if d.will_break(flat):
                out.append(d.EXPAND_PARENT)
            out.append(d.best_fitting(flat, d.group(flat, expand=True), ["(", *d.block_indent(flat), ")"]))
            return out
        if self.own_parentheses(body):
            return out + self.expr(body)
        return out + self.parenthesize_if_expands(lambda: self.expr(body, Parens.NEVER))

    # -- comprehensions ------------------------------------------------------------------------

    def comprehensions(self, generators: list[ast.comprehension]) -> list[Element]:
        out: list[Element] = []
        for i, gen in enumerate(generators):
            if i:
                out.append(Line.SOFT_OR_SPACE)
            if gen.is_async:
                out += ["async", " "]
            target = gen.target
            target_doc = self.tuple_without_parentheses(target)
            out += ["for", " ", *target_doc, " ", "in", " ", *self.expr(gen.iter)]
            for condition in gen.ifs:
                out += [Line.SOFT_OR_SPACE, "if", " ", *self.expr(condition)]
        return out

    def tuple_without_parentheses(self, node: ast.expr) -> list[Element]:
        if isinstance(node, ast.Tuple) and not self.source.own_parentheses(node):
            out: list[Element] = []
            for i, element in enumerate(node.elts):
                if i:
                    out += d.group(",", " ")
                out += self.expr(element)
            return out
        return self.expr(node)

    def generator(self, node: ast.GeneratorExp, *, sole_argument: bool = False) -> list[Element]:
        if sole_argument and not self.source.own_parentheses(node):
            return [*d.group(self.expr(node.elt)), Line.SOFT_OR_SPACE, *self.comprehensions(node.generators)]

        def inside() -> list[Element]:
            return d.group(d.group(self.expr(node.elt)), Line.SOFT_OR_SPACE, self.comprehensions(node.generators))

        return self.parenthesized("(", inside, ")")

    def fmt_GeneratorExp(self, node: ast.GeneratorExp) -> list[Element]:
        return self.generator(node)

    def fmt_ListComp(self, node: ast.ListComp) -> list[Element]:
        def inside() -> list[Element]:
            return d.group(d.group(self.expr(node.elt)), Line.SOFT_OR_SPACE, self.comprehensions(node.generators))

        return self.parenthesized("[", inside, "]")

    def fmt_SetComp(self, node: ast.SetComp) -> list[Element]:
        def inside() -> list[Element]:
            return d.group(d.group(self.expr(node.elt)), Line.SOFT_OR_SPACE, self.comprehensions(node.generators))

        return self.parenthesized("{", inside, "}")

    def fmt_DictComp(self, node: ast.DictComp) -> list[Element]:
        def inside() -> list[Element]:
            key = [*d.group(self.expr(node.key)), ":", " "]
            return d.group(key, self.expr(node.value), Line.SOFT_OR_SPACE, self.comprehensions(node.generators))

        return self.parenthesized("{", inside, "}")

    # -- whether optional parentheses can be left out ----------------------------------------------

    def own_parentheses(self, node: ast.expr) -> str | None:
        """Whether the expression has brackets of its own: "non-empty", "empty" or None."""
        if isinstance(node, ast.ListComp | ast.SetComp | ast.DictComp | ast.Subscript):
            return "non-empty"
        if isinstance(node, ast.GeneratorExp):
            return "non-empty" if self.source.own_parentheses(node) else None
        if isinstance(node, ast.List | ast.Set):
            return "non-empty" if node.elts else "empty"
        if isinstance(node, ast.Tuple):
            if not self.source.own_parentheses(node):
                return None
            return "non-empty" if node.elts else "empty"
        if isinstance(node, ast.Dict):
            return "non-empty" if node.keys else "empty"
        if isinstance(node, ast.Call):
            return "non-empty" if node.args or node.keywords else "empty"
        return None

    def has_parentheses(self, node: ast.expr) -> str | None:
        own = self.own_parentheses(node)
        if own != "non-empty" and self.source.is_parenthesized(node):
            return "non-empty"
        return own

    def can_omit_optional_parentheses(self, node: ast.expr) -> bool:
        visitor = _OmitVisitor(self)
        visitor.visit_subexpression(node)
        if not visitor.any_parenthesized:
            return False
        if visitor.max_count > 1:
            return False
        if visitor.max_precedence in (Precedence.NONE, Precedence.ATTRIBUTE):
            return True

        def ends_in_brackets(e: ast.expr | None) -> bool:
            return e is not None and not isinstance(e, ast.Subscript) and self.has_parentheses(e) == "non-empty"

        return ends_in_brackets(visitor.last) or ends_in_brackets(visitor.first)


class _OmitVisitor:
    """How many operators of the loosest precedence an expression has, and what it starts and ends
    with: optional parentheses may be left out when it ends (or starts) with brackets to break."""

    def __init__(self, layout: OperatorLayout) -> None:
        self.layout = layout
        self.max_precedence = Precedence.NONE
        self.max_count = 0
        self.any_parenthesized = False
        self.last: ast.expr | None = None
        self.first: ast.expr | None = None
        self.first_set = False  # the first thing may be a token (``not``, ``lambda``): first stays None

    def update(self, precedence: Precedence, count: int = 1) -> None:
        if precedence > self.max_precedence:
            self.max_precedence, self.max_count = precedence, count
        elif precedence == self.max_precedence:
            self.max_count += count

    def set_first(self, node: ast.expr | None) -> None:
        if not self.first_set:
            self.first, self.first_set = node, True

    def visit(self, node: ast.expr) -> None:
        self.last = node
        if self.layout.source.is_parenthesized(node):
            self.any_parenthesized = True
        else:
            self.visit_subexpression(node)
        self.set_first(node)

    def visit_subexpression(self, node: ast.expr) -> None:
        source = self.layout.source
        if isinstance(node, ast.Dict | ast.List | ast.Set | ast.ListComp | ast.SetComp | ast.DictComp):
            self.any_parenthesized = True
            return
        if isinstance(node, ast.Tuple | ast.GeneratorExp) and source.own_parentheses(node):
            self.any_parenthesized = True
            return
        if isinstance(node, ast.BoolOp):
            self.update(Precedence.BOOLEAN, len(node.values) - 1)
        elif isinstance(node, ast.BinOp):
            self.update(BINARY[type(node.op)][1])
        elif isinstance(node, ast.IfExp):
            self.update(Precedence.CONDITIONAL, 2)
        elif isinstance(node, ast.Compare):
            self.update(Precedence.COMPARATOR, len(node.ops))
        elif isinstance(node, ast.Call):
            self.any_parenthesized = True
            self.visit(node.func)
            self.last = node
            return
        elif isinstance(node, ast.Subscript):
            self.any_parenthesized = True
            self.visit(node.value)
            self.last = node
            return
        elif isinstance(node, ast.Attribute):
            self.visit(node.value)
            if self.layout.has_parentheses(node.value) is not None:
                self.update(Precedence.ATTRIBUTE)
            self.last = node
            return
        elif isinstance(node, ast.UnaryOp):
            if isinstance(node.op, ast.Invert):
                self.update(Precedence.BITWISE_INVERSION)
            self.set_first(None)
        elif isinstance(node, ast.Lambda | ast.Await | ast.Yield | ast.YieldFrom | ast.Starred):
            self.set_first(None)
        elif not isinstance(node, ast.NamedExpr | ast.GeneratorExp | ast.Tuple):
            return  # names, literals, slices: nothing inside to visit
        for child in _children_in_source_order(node):
            self.visit(child)


def _children_in_source_order(node: ast.expr) -> list[ast.expr]:
    if isinstance(node, ast.IfExp):
        return [node.body, node.test, node.orelse]
    out: list[ast.expr] = []
    for child in ast.iter_child_nodes(node):
        if isinstance(child, ast.expr):
            out.append(child)
        elif isinstance(child, ast.comprehension):
            out += [child.target, child.iter, *child.ifs]
    return out

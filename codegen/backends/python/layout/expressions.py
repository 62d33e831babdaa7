"""Expressions with brackets or none: names, literals, strings, calls, attributes, subscripts,
tuples, lists, sets and dicts, as ruff lays them out.

Calls and bracketed literals break inside their brackets: the items go on one line of their own
when they fit there (calls only), else one per line with a trailing comma added. A trailing
comma written in the source keeps a bracket broken (ruff's magic trailing comma).
"""

from __future__ import annotations

import ast
import enum

from . import document as d
from .context import Parens
from .document import Element
from .operators import OperatorLayout
from .source import joined_strings, normalize_number, normalize_string


class TupleParens(enum.Enum):
    DEFAULT = "default"
    PRESERVE = "preserve"
    OPTIONAL = "optional parentheses"
    NEVER = "never"


class ExpressionLayout(OperatorLayout):
    def fmt_Name(self, node: ast.Name) -> list[Element]:
        return [node.id]

    def fmt_Constant(self, node: ast.Constant) -> list[Element]:
        if isinstance(node.value, str | bytes):
            return self.string(node)
        text = self.source.segment(node)
        if isinstance(node.value, int | float | complex) and not isinstance(node.value, bool):
            return [normalize_number(text)]
        return [text]

    def fmt_JoinedStr(self, node: ast.JoinedStr) -> list[Element]:
        parts = self.source.string_parts(node)
        if len(parts) != 1:
            raise NotImplementedError("implicitly concatenated f-string")
        return [normalize_string(parts[0])]

    def string(self, node: ast.expr) -> list[Element]:
        parts = self.source.string_parts(node)
        if len(parts) == 1:
            return [normalize_string(parts[0])]
        flat = joined_strings(parts)
        if flat is None:
            raise NotImplementedError("implicit concatenation that cannot be joined")
        if not self.level.parenthesized:
            return [flat]
        expanded = self.implicit_parts(node)
        return self.in_parens_only_group([*d.if_group_fits_on_line(flat), *d.if_group_breaks(expanded)])

    def implicit_parts(self, node: ast.expr) -> list[Element]:
        """The parts of an implicitly concatenated string, each on a line of its own when broken."""
        out: list[Element] = []
        for i, part in enumerate(self.source.string_parts(node)):
            if i:
                out += self.in_parens_only_line()
            out.append(normalize_string(part))
        return out

    def fmt_Attribute(self, node: ast.Attribute) -> list[Element]:
        value = node.value
        base_ten = isinstance(value, ast.Constant) and isinstance(value.value, int | float)
        if base_ten:
            base_ten = self.source.segment(value)[:2].lower() not in ("0x", "0o", "0b")
        parens = Parens.ALWAYS if base_ten or self.source.is_parenthesized(value) else Parens.NEVER
        return [*self.expr(value, parens), ".", node.attr]

    def fmt_Call(self, node: ast.Call) -> list[Element]:
        func = self.expr(node.func, Parens.ALWAYS if self.source.is_parenthesized(node.func) else Parens.NEVER)
        if not node.args and not node.keywords:
            return [*func, "()"]

        def arguments() -> list[Element]:
            if len(node.args) == 1 and not node.keywords:
                (arg,) = node.args
                if isinstance(arg, ast.GeneratorExp):
                    items = [self.generator(arg, sole_argument=True)]
                else:
                    items = [self.expr(arg, Parens.ALWAYS if self.source.is_parenthesized(arg) else Parens.NEVER)]
            else:
                entries: list[tuple[int, ast.expr | ast.keyword]] = [(self.source.span(a)[0], a) for a in node.args]
                entries += [(self.source.span(k)[0], k) for k in node.keywords]
                items = [
                    self.keyword(e) if isinstance(e, ast.keyword) else self.expr(e)
                    for _, e in sorted(entries, key=lambda e: e[0])
                ]
            return d.group(self.comma_separated(items, node))

        return [*func, *self.parenthesized("(", arguments, ")")]

    def keyword(self, keyword: ast.keyword) -> list[Element]:
        if keyword.arg is None:
            return ["**", *self.expr(keyword.value)]
        return [keyword.arg, "=", *self.expr(keyword.value)]

    def fmt_Subscript(self, node: ast.Subscript) -> list[Element]:
        value = self.expr(node.value, Parens.ALWAYS if self.source.is_parenthesized(node.value) else Parens.NEVER)
        index = node.slice

        def inside() -> list[Element]:
            if isinstance(index, ast.Tuple):
                return self.tuple(index, TupleParens.PRESERVE)
            return self.expr(index)

        return [*value, *self.parenthesized("[", inside, "]")]

    def fmt_Tuple(self, node: ast.Tuple) -> list[Element]:
        return self.tuple(node, TupleParens.DEFAULT)

    def tuple(self, node: ast.Tuple, parens: TupleParens) -> list[Element]:
        own = self.source.own_parentheses(node)
        if not node.elts:
            return ["()"]
        if len(node.elts) == 1:
            single = node.elts[0]
            return self.parenthesized("(", lambda: [*self.expr(single), ","], ")")

        def sequence() -> list[Element]:
            return self.comma_separated([self.expr(e) for e in node.elts], node if own else None)

        if own:
            return self.parenthesized("(", sequence, ")")
        if parens is TupleParens.NEVER:
            out: list[Element] = []
            for i, e in enumerate(node.elts):
                if i:
                    out += d.group(",", " ")
                out += self.expr(e)
            return out
        if parens is TupleParens.PRESERVE:
            return d.group(sequence())
        if parens is TupleParens.OPTIONAL and len(node.elts) == 2:
            return self.optional_parentheses(sequence)
        return self.parenthesize_if_expands(sequence)

    def bracketed(self, left: str, items: list[ast.expr], node: ast.expr, right: str) -> list[Element]:
        if not items:
            return [left + right]
        return self.parenthesized(left, lambda: self.comma_separated([self.expr(e) for e in items], node), right)

    def fmt_List(self, node: ast.List) -> list[Element]:
        return self.bracketed("[", node.elts, node, "]")

    def fmt_Set(self, node: ast.Set) -> list[Element]:
        return self.bracketed("{", node.elts, node, "}")

    def fmt_Dict(self, node: ast.Dict) -> list[Element]:
        if not node.keys:
            return ["{}"]

        def pairs() -> list[Element]:
            items: list[list[Element]] = []
            for key, value in zip(node.keys, node.values, strict=True):
                if key is None:
                    items.append(d.group("**", self.expr(value)))
                else:
                    items.append(d.group(self.expr(key), ":", " ", self.expr(value)))
            return self.comma_separated(items, node)

        return self.parenthesized("{", pairs, "}")

    def fmt_Starred(self, node: ast.Starred) -> list[Element]:
        return ["*", *self.expr(node.value)]

    def fmt_Slice(self, node: ast.Slice) -> list[Element]:
        def simple(e: ast.expr | None) -> bool:
            while isinstance(e, ast.UnaryOp) and not isinstance(e.op, ast.Not):
                e = e.operand
            return e is None or isinstance(e, ast.Constant | ast.Name)

        all_simple = simple(node.lower) and simple(node.upper) and simple(node.step)
        out: list[Element] = []
        if node.lower is not None:
            out += self.expr(node.lower)
            if not all_simple:
                out.append(" ")
        out.append(":")
        if node.upper is not None:
            if not all_simple:
                out.append(" ")
            out += self.expr(node.upper)
        if node.step is not None:
            out += [" :" if not all_simple else ":", *([" "] if not all_simple else []), *self.expr(node.step)]
        return out

"""Statements as documents: assignments, expression statements, ``return``, ``raise`` and the
headers of ``if`` / ``elif`` / ``while`` / ``for``, as ruff lays them out.

An assignment whose value does not fit tries, in order: the value broken inside its own brackets,
the value in parentheses, the target broken (ruff's ``best_fitting`` choices).
"""

from __future__ import annotations

import ast

from . import document as d
from .context import Level, Needs, Parens, Parenthesize
from .document import Element, Line
from .expressions import ExpressionLayout, TupleParens
from .operators import BINARY
from .source import joined_strings


def _all_parameters(params: ast.arguments) -> list[ast.AST]:
    """Every parameter and default, in source order (the last one decides a trailing comma)."""
    nodes: list[ast.AST] = [*params.posonlyargs, *params.args]
    if params.vararg is not None:
        nodes.append(params.vararg)
    nodes += params.kwonlyargs
    if params.kwarg is not None:
        nodes.append(params.kwarg)
    nodes += [e for e in (*params.defaults, *params.kw_defaults) if e is not None]
    return sorted(nodes, key=lambda n: (getattr(n, "lineno", 0), getattr(n, "col_offset", 0)))


_ARITHMETIC = (ast.BitOr, ast.BitXor, ast.LShift, ast.RShift, ast.Add, ast.Sub)


class StatementLayout(ExpressionLayout):
    def statement(self, node: ast.stmt) -> list[Element]:
        if isinstance(node, ast.Expr):
            value = node.value
            if isinstance(value, ast.BinOp) and isinstance(value.op, _ARITHMETIC):
                return self.maybe_parenthesize(value, node, Parenthesize.OPTIONAL)
            return self.expr(value)
        if isinstance(node, ast.Assign):
            return self.assign(node)
        if isinstance(node, ast.AnnAssign):
            return self.annotated_assign(node)
        if isinstance(node, ast.AugAssign):
            operator = BINARY[type(node.op)][0] + "="
            if self.target_has_own_parentheses(node.target) and not self.source.is_parenthesized(node.target):
                return self.right_to_left(node.target, operator, node.value, node)
            return [*self.expr(node.target), " ", operator, " ", *self.left_to_right(node.value, node)]
        if isinstance(node, ast.Return):
            if node.value is None:
                return ["return"]
            if isinstance(node.value, ast.Tuple):
                return ["return", " ", *self.tuple(node.value, TupleParens.OPTIONAL)]
            return ["return", " ", *self.left_to_right(node.value, node)]
        if isinstance(node, ast.ImportFrom):
            return self.import_from(node)
        if isinstance(node, ast.Raise):
            out: list[Element] = ["raise"]
            if node.exc is not None:
                out += [" ", *self.maybe_parenthesize(node.exc, node, Parenthesize.OPTIONAL)]
            if node.cause is not None:
                out += [" ", "from", " ", *self.maybe_parenthesize(node.cause, node, Parenthesize.OPTIONAL)]
            return out
        raise NotImplementedError(type(node).__name__)

    def import_from(self, node: ast.ImportFrom) -> list[Element]:
        """``from module import a, b``: in parentheses, one name per line, when too long."""
        head: list[Element] = ["from", " ", "." * node.level + (node.module or ""), " ", "import", " "]
        if len(node.names) == 1 and node.names[0].name == "*":
            return [*head, "*"]

        def names() -> list[Element]:
            out: list[Element] = []
            for i, alias in enumerate(node.names):
                if i:
                    out += [",", Line.SOFT_OR_SPACE]
                out += [alias.name] if alias.asname is None else [alias.name, " ", "as", " ", alias.asname]
            out += d.if_group_breaks(",")
            text = self.source.text.rstrip()
            if text.endswith(")") and text[:-1].rstrip().endswith(","):
                out.append(d.EXPAND_PARENT)  # a trailing comma keeps the names one per line
            return out

        return [*head, *self.parenthesize_if_expands(names)]

    def function_header(self, node: ast.FunctionDef | ast.AsyncFunctionDef) -> list[Element]:
        """``def name(parameters) -> annotation:``: parameters break first, one per line if need be."""
        out: list[Element] = ["async", " "] if isinstance(node, ast.AsyncFunctionDef) else []
        out += ["def", " ", node.name]
        if getattr(node, "type_params", None):
            raise NotImplementedError("type parameters")
        inner = self.parameters(node.args)
        returns = node.returns
        if returns is not None:
            inner += [" ", "->", " "]
            if isinstance(returns, ast.Tuple):
                inner += self.expr(returns, Parens.NEVER)
            else:
                empty = not _all_parameters(node.args)
                how = Parenthesize.IF_BREAKS_PARENTHESIZED if empty else Parenthesize.IF_BREAKS
                inner += self.maybe_parenthesize(returns, node, how)
        return [*out, *d.group(inner), ":"]

    def parameters(self, params: ast.arguments) -> list[Element]:
        every = _all_parameters(params)
        if not every:
            return ["()"]
        with self.at(Level("parenthesized")):
            entries: list[list[Element]] = []
            defaults = [None] * (len(params.posonlyargs) + len(params.args) - len(params.defaults))
            positional = [*params.posonlyargs, *params.args]
            for i, (arg, default) in enumerate(zip(positional, [*defaults, *params.defaults], strict=True)):
                entries.append(self.parameter(arg, default))
                if params.posonlyargs and i == len(params.posonlyargs) - 1:
                    entries.append(["/"])
            if params.vararg is not None:
                entries.append(["*", *self.parameter(params.vararg, None)])
            elif params.kwonlyargs:
                entries.append(["*"])
            for arg, kw_default in zip(params.kwonlyargs, params.kw_defaults, strict=True):
                entries.append(self.parameter(arg, kw_default))
            if params.kwarg is not None:
                entries.append(["**", *self.parameter(params.kwarg, None)])
            inner: list[Element] = []
            for i, entry in enumerate(entries):
                if i:
                    inner += [",", Line.SOFT_OR_SPACE]
                inner += entry
            inner += d.if_group_breaks(",")
            last = every[-1]
            after = self.source.span(last)[1]
            if self.source.text[after:].lstrip(" ").startswith(","):
                inner.append(Line.HARD)  # a trailing comma keeps the parameters one per line
        single = len(every) == 1 and not params.posonlyargs and not params.kwonlyargs
        return ["(", *d.soft_block_indent(inner if single else d.group(inner)), ")"]

    def parameter(self, arg: ast.arg, default: ast.expr | None) -> list[Element]:
        out: list[Element] = [arg.arg]
        if arg.annotation is not None:
            out += [":", " ", *self.expr(arg.annotation)]
        if default is not None:
            out += [" = " if arg.annotation is not None else "=", *self.expr(default)]
        return out

    def header(self, keyword: str, node: ast.If | ast.While | ast.For) -> list[Element]:
        if isinstance(node, ast.For):
            iterable = self.maybe_parenthesize(node.iter, node, Parenthesize.IF_BREAKS)
            return ["for", " ", *self.tuple_without_parentheses(node.target), " ", "in", " ", *iterable, ":"]
        return [keyword, " ", *self.maybe_parenthesize(node.test, node, Parenthesize.IF_BREAKS), ":"]

    # -- assignments ---------------------------------------------------------------------------

    def assign(self, node: ast.Assign) -> list[Element]:
        if len(node.targets) != 1:
            raise NotImplementedError("chained assignment")
        (target,) = node.targets
        if self.target_has_own_parentheses(target) and not self.source.is_parenthesized(target):
            return self.right_to_left(target, "=", node.value, node)
        return [*self.expr(target), " ", "=", " ", *self.left_to_right(node.value, node)]

    def annotated_assign(self, node: ast.AnnAssign) -> list[Element]:
        out = [*self.expr(node.target), ":", " "]
        annotation, value = node.annotation, node.value
        needs = self.needs_parentheses(annotation, node)
        if value is None:
            if needs is Needs.ALWAYS:
                return out + self.expr(annotation, Parens.ALWAYS)
            return out + self.left_to_right(annotation, node)
        if needs is not Needs.ALWAYS and self.splittable(annotation):
            return out + self.right_to_left(annotation, "=", value, node)
        annotation_doc = self.expr(annotation, Parens.ALWAYS if needs is Needs.ALWAYS else Parens.NEVER)
        return [*out, *annotation_doc, " ", "=", " ", *self.left_to_right(value, node)]

    def inlines_comments(self, value: ast.expr, statement: ast.stmt) -> bool:
        """A value that cannot break (name, number, one-part string): parenthesized only to fit."""
        if isinstance(value, ast.Name):
            return True
        if isinstance(value, ast.Constant):
            if isinstance(value.value, str | bytes):
                return self.needs_parentheses(value, statement) is Needs.BEST_FIT
            return True
        if isinstance(value, ast.JoinedStr):
            return self.needs_parentheses(value, statement) is Needs.BEST_FIT
        return False

    def implicit_flat(self, value: ast.expr) -> str | None:
        if isinstance(value, ast.Constant) and isinstance(value.value, str | bytes):
            parts = self.source.string_parts(value)
            if len(parts) > 1:
                return joined_strings(parts)
        return None

    def value_in_parentheses_if_breaks(self, value: ast.expr, statement: ast.stmt) -> list[Element]:
        if isinstance(value, ast.Lambda):
            raise NotImplementedError("lambda assigned")
        return self.maybe_parenthesize(value, statement, Parenthesize.IF_BREAKS)

    def left_to_right(self, value: ast.expr, statement: ast.stmt) -> list[Element]:
        """The value after ``return`` or after the ``=`` of a target that cannot break."""
        flat = self.implicit_flat(value)
        if not self.inlines_comments(value, statement) and flat is None:
            return self.value_in_parentheses_if_breaks(value, statement)
        group_id = d.new_group_id()
        if flat is not None:
            with self.at(Level("expression", group_id)):
                parts = self.implicit_parts(value)
            joined = d.group("(", d.soft_block_indent(flat), ")", group_id=group_id, expand=True)
            expanded = d.group("(", d.block_indent(parts), ")", group_id=group_id, expand=True)
            return [d.best_fitting([flat], joined, expanded, measure=d.Measure.ALL_LINES)]
        return d.best_fit_parenthesize(self.expr(value, Parens.NEVER), group_id=group_id)

    def right_to_left(self, before: ast.expr, operator: str, value: ast.expr, statement: ast.stmt) -> list[Element]:
        """``before operator value`` where ``before`` (a target or annotation) may break too."""
        best_fit = isinstance(value, ast.Attribute | ast.Call | ast.Subscript) and (
            self.needs_parentheses(value, statement) is Needs.BEST_FIT
        )
        if not self.inlines_comments(value, statement) and not best_fit and self.implicit_flat(value) is None:
            value_doc = self.value_in_parentheses_if_breaks(value, statement)
            return [*self.before_operator(before), " ", operator, " ", *value_doc]
        if self.implicit_flat(value) is not None:
            raise NotImplementedError("implicitly concatenated string after a target that can break")
        target = self.before_operator(before)
        formatted = self.expr(value, Parens.NEVER)
        if d.will_break(target):
            return [*target, " ", operator, " ", *formatted]
        single_line = [*target, " ", operator, " ", *formatted]
        parenthesized = [*target, " ", operator, " ", "(", *d.group(d.soft_block_indent(formatted), expand=True), ")"]
        split_target = [*d.group(target, expand=True), " ", operator, " ", *formatted]
        if isinstance(value, ast.Call | ast.Subscript | ast.Attribute):
            own_brackets = [*target, " ", operator, " ", *d.group(formatted, expand=True)]
            return [d.best_fitting(single_line, own_brackets, parenthesized, split_target)]
        return [d.best_fitting(single_line, parenthesized, split_target)]

    def before_operator(self, node: ast.expr) -> list[Element]:
        if self.target_has_own_parentheses(node) or self.attribute_with_parenthesized_value(node):
            return self.expr(node, Parens.NEVER)
        if self.can_omit_optional_parentheses(node):
            return self.optional_parentheses(lambda: self.expr(node, Parens.NEVER))
        return self.parenthesize_if_expands(lambda: self.expr(node, Parens.NEVER))

    def target_has_own_parentheses(self, node: ast.expr) -> bool:
        return isinstance(node, ast.Tuple) or self.own_parentheses(node) is not None

    def attribute_with_parenthesized_value(self, node: ast.expr) -> bool:
        if isinstance(node, ast.Attribute):
            return self.has_parentheses(node.value) is not None or self.attribute_with_parenthesized_value(node.value)
        if isinstance(node, ast.Subscript):
            return True
        if isinstance(node, ast.Call):
            return bool(node.args or node.keywords)
        return False

    def splittable(self, node: ast.expr) -> bool:
        """Whether the expression has any place to break at all."""
        if isinstance(node, ast.NamedExpr | ast.Name | ast.Slice):
            return False
        if isinstance(node, ast.Constant):
            return isinstance(node.value, str | bytes) and len(self.source.string_parts(node)) > 1
        if isinstance(node, ast.Tuple | ast.List | ast.Set):
            return bool(node.elts)
        if isinstance(node, ast.Dict):
            return bool(node.keys)
        if isinstance(node, ast.UnaryOp):
            return self.splittable(node.operand)
        if isinstance(node, ast.Call):
            return bool(node.args or node.keywords) or self.source.is_parenthesized(node.func)
        if isinstance(node, ast.JoinedStr):
            return len(self.source.string_parts(node)) > 1
        if isinstance(node, ast.Lambda | ast.Starred | ast.Attribute):
            inner = node.body if isinstance(node, ast.Lambda) else node.value
            return self.source.is_parenthesized(inner) or self.splittable(inner)
        return True

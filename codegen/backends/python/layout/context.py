"""What encloses an expression being laid out, and the pieces whose layout depends on it.

``Level`` says what encloses the expression: nothing (a statement), optional parentheses that may
still appear (their group id), or real brackets. A line may only break inside brackets, so the
same binary operator is a possible break inside a call and a plain space at statement level; a
statement that needs its expression to break gives it optional parentheses, which appear only
when they help (ruff's rules, ``maybe_parenthesize_expression``).
"""

from __future__ import annotations

import ast
import enum
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass

from . import document as d
from .document import Element, Line
from .source import Source


class Parens(enum.Enum):
    PRESERVE = "preserve"  # as written in the source
    ALWAYS = "always"
    NEVER = "never"


class Needs(enum.Enum):
    """When an expression needs parentheses to break across lines (ruff's OptionalParentheses)."""

    MULTILINE = "multiline"
    ALWAYS = "always"
    BEST_FIT = "best fit"
    NEVER = "never"


class Parenthesize(enum.Enum):
    """What a statement asks of an expression it holds (ruff's Parenthesize)."""

    OPTIONAL = "optional"
    IF_BREAKS = "if breaks"
    IF_REQUIRED = "if required"
    IF_BREAKS_PARENTHESIZED = "if breaks parenthesized"


@dataclass(frozen=True)
class Level:
    kind: str  # "statement", "expression" or "parenthesized"
    group_id: int | None = None  # "expression" inside optional parentheses

    @property
    def parenthesized(self) -> bool:
        return self.kind == "parenthesized" or self.group_id is not None


STATEMENT = Level("statement")
EXPRESSION = Level("expression")
PARENTHESIZED = Level("parenthesized")


class LayoutContext:
    def __init__(self, source: Source) -> None:
        self.source = source
        self.level = STATEMENT

    @contextmanager
    def at(self, level: Level) -> Iterator[None]:
        saved, self.level = self.level, level
        try:
            yield
        finally:
            self.level = saved

    # -- context-dependent pieces (break only where brackets make it legal) ----------------------

    def in_parens_only_group(self, content: list[Element]) -> list[Element]:
        level = self.level
        if level.group_id is not None:
            return d.conditional_group(content, condition=d.Condition(d.Mode.EXPANDED, level.group_id))
        if level.kind == "parenthesized":
            return d.group(content)
        return content

    def in_parens_only_line(self, *, space: bool = True) -> list[Element]:
        level = self.level
        if level.group_id is not None:
            line = Line.SOFT_OR_SPACE if space else Line.SOFT
            return [
                *d.if_group_breaks(line, group_id=level.group_id),
                *(d.if_group_fits_on_line(" ", group_id=level.group_id) if space else []),
            ]
        if level.kind == "parenthesized":
            return [Line.SOFT_OR_SPACE if space else Line.SOFT]
        return [" "] if space else []

    def parenthesized(self, left: str, content: Callable[[], list[Element]], right: str) -> list[Element]:
        current = self.level
        with self.at(PARENTHESIZED):
            inner = d.group(d.soft_block_indent(content()))
        if current.group_id is not None:
            # breaking inside these brackets must not make the optional parentheses appear
            inner = d.fits_expanded(inner, condition=d.Condition(d.Mode.FLAT, current.group_id))
        return [left, *inner, right]

    def optional_parentheses(self, content: Callable[[], list[Element]]) -> list[Element]:
        group_id = d.new_group_id()
        with self.at(Level("expression", group_id)):
            inner = content()
        return _parentheses_if_breaks(inner, group_id)

    def parenthesize_if_expands(self, content: Callable[[], list[Element]]) -> list[Element]:
        with self.at(PARENTHESIZED):
            inner = content()
        return _parentheses_if_breaks(inner, d.new_group_id())

    def comma_separated(self, items: list[list[Element]], bracketed: ast.AST | None) -> list[Element]:
        """Items joined by commas that break; a trailing comma when broken (and a magic one kept)."""
        out: list[Element] = []
        for i, item in enumerate(items):
            if i:
                out += [",", Line.SOFT_OR_SPACE]
            out += item
        magic = bracketed is not None and self.source.magic_trailing_comma(bracketed)
        if items and (magic or len(items) > 1):
            out += d.if_group_breaks(",")
        if items and magic:
            out.append(d.EXPAND_PARENT)
        return out

    # -- expressions ---------------------------------------------------------------------------

    def node(self, node: ast.expr) -> list[Element]:
        """The expression without parentheses around it (each kind has a ``fmt_<Kind>`` method)."""
        method = getattr(self, "fmt_" + type(node).__name__, None)
        if method is None:
            raise NotImplementedError(type(node).__name__)
        result: list[Element] = method(node)
        return result

    def can_omit_optional_parentheses(self, node: ast.expr) -> bool:
        raise NotImplementedError

    def expr(self, node: ast.expr, parens: Parens = Parens.PRESERVE) -> list[Element]:
        parenthesize = parens is Parens.ALWAYS or (parens is Parens.PRESERVE and self.source.is_parenthesized(node))
        if parenthesize:
            return self.parenthesized("(", lambda: self.node(node), ")")
        level = EXPRESSION if self.level.kind == "statement" else self.level
        with self.at(level):
            return self.node(node)

    def maybe_parenthesize(self, node: ast.expr, parent: ast.AST, parenthesize: Parenthesize) -> list[Element]:
        """An expression a statement holds, in parentheses only where it needs them to break."""
        if parenthesize is Parenthesize.OPTIONAL and self.source.is_parenthesized(node):
            return self.expr(node, Parens.ALWAYS)
        needs = self.needs_parentheses(node, parent)
        if needs is not Needs.ALWAYS and self.level.parenthesized:
            return self.expr(node, Parens.NEVER)
        if needs is Needs.MULTILINE:
            if parenthesize is Parenthesize.IF_REQUIRED:
                return self.expr(node, Parens.NEVER)
            if self.can_omit_optional_parentheses(node):
                return self.optional_parentheses(lambda: self.expr(node, Parens.NEVER))
            return self.parenthesize_if_expands(lambda: self.expr(node, Parens.NEVER))
        if needs is Needs.BEST_FIT:
            if parenthesize is Parenthesize.IF_BREAKS_PARENTHESIZED:
                if self.can_omit_optional_parentheses(node):
                    return self.optional_parentheses(lambda: self.expr(node, Parens.NEVER))
                return self.parenthesize_if_expands(lambda: self.expr(node, Parens.NEVER))
            if parenthesize is Parenthesize.IF_BREAKS:
                group_id = d.new_group_id()
                with self.at(Level("expression", group_id)):
                    inner = self.expr(node, Parens.NEVER)
                return d.best_fit_parenthesize(inner, group_id=group_id)
            return self.expr(node, Parens.NEVER)
        if needs is Needs.ALWAYS:
            return self.expr(node, Parens.ALWAYS)
        return self.expr(node, Parens.NEVER)

    # -- what a statement may do with an expression ----------------------------------------------

    def needs_parentheses(self, node: ast.expr, parent: ast.AST) -> Needs:
        if isinstance(node, ast.Name):
            return Needs.BEST_FIT
        if isinstance(node, ast.Constant):
            if isinstance(node.value, str | bytes) and len(self.source.string_parts(node)) > 1:
                return Needs.MULTILINE
            return Needs.BEST_FIT
        if isinstance(node, ast.JoinedStr):
            return Needs.BEST_FIT
        if isinstance(node, ast.Call):
            if self.source.is_parenthesized(node.func):
                return Needs.NEVER
            return self.needs_parentheses(node.func, node)
        if isinstance(node, ast.Attribute | ast.Subscript):
            if self.source.is_parenthesized(node.value):
                return Needs.NEVER
            needs = self.needs_parentheses(node.value, node)
            functions = ast.FunctionDef | ast.AsyncFunctionDef
            if isinstance(node, ast.Subscript) and isinstance(parent, functions) and parent.returns is node:
                if needs is Needs.BEST_FIT:  # a return annotation breaks in its brackets, after the parameters
                    p = parent.args
                    empty = not (p.posonlyargs or p.args or p.vararg or p.kwonlyargs or p.kwarg)
                    return Needs.MULTILINE if empty else Needs.NEVER
            return needs
        if isinstance(node, ast.UnaryOp):
            if self.source.is_parenthesized(node.operand):
                return Needs.NEVER
            return self.needs_parentheses(node.operand, node)
        if isinstance(node, ast.NamedExpr):
            statements = ast.Assign | ast.AnnAssign | ast.AugAssign | ast.Assert | ast.Return | ast.For
            return Needs.ALWAYS if isinstance(parent, statements | ast.Lambda) else Needs.MULTILINE
        if isinstance(node, ast.Tuple | ast.List | ast.Set | ast.Dict | ast.ListComp | ast.SetComp | ast.DictComp):
            return Needs.NEVER
        if isinstance(node, ast.GeneratorExp):
            return Needs.NEVER
        return Needs.MULTILINE


def _parentheses_if_breaks(inner: list[Element], group_id: int) -> list[Element]:
    """``inner`` in a group (``group_id``) that shows parentheses, and indents, only when it breaks."""
    return d.group(
        d.if_group_breaks("("),
        d.indent_if_group_breaks(Line.SOFT, inner, group_id=group_id),
        Line.SOFT,
        d.if_group_breaks(")"),
        group_id=group_id,
    )

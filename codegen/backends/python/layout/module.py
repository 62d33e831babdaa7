"""Lays out every one-line statement of a module: the entry point of the layout engine."""

from __future__ import annotations

import ast
import io
import tokenize

from .printer import Printer
from .source import Source
from .statements import StatementLayout

LINE_LENGTH = 120
_INDENT = 4
_SIMPLE = ast.Expr | ast.Assign | ast.AnnAssign | ast.AugAssign | ast.Return | ast.Raise
_HEADERS = ast.If | ast.While | ast.For


def format_module(text: str, line_length: int = LINE_LENGTH) -> str:
    """``text`` with its statements laid out as ruff lays them out.

    Simple statements and the headers of ``if``/``elif``/``while``/``for`` are laid out afresh
    from their tokens (a statement written over several lines is first joined into one: only a
    trailing comma before a closing bracket keeps it broken, as in ruff); a statement with a
    comment or a triple-quoted string in it is kept as written.
    """
    lines = text.split("\n")
    kept = _rows_with_comments_or_long_strings(text)
    replaced: dict[int, tuple[int, str]] = {}  # first row -> (last row, new text)
    for node in _statements(ast.parse(text).body):
        first = node.lineno - 1
        if isinstance(node, _SIMPLE) and not _is_docstring(node):
            last = (node.end_lineno or node.lineno) - 1
        elif isinstance(node, _HEADERS):
            tested = node.iter if isinstance(node, ast.For) else node.test
            last = (tested.end_lineno or tested.lineno) - 1
            if node.body[0].lineno - 1 <= last:
                continue
        else:
            continue
        if any(row in kept for row in range(first, last + 1)):
            continue
        line = lines[first]
        stripped = line.lstrip(" ")
        depth, rest = divmod(len(line) - len(stripped), _INDENT)
        if rest:
            continue
        joined = " ".join([stripped.strip(), *(lines[row].strip() for row in range(first + 1, last + 1))])
        if isinstance(node, _HEADERS):
            if not joined.endswith(":"):
                continue
            laid_out = _layout_header(joined, line_length, depth)
        else:
            laid_out = _layout_simple(joined, line_length, depth)
        if laid_out is not None:
            replaced[first] = (last, laid_out)
    out: list[str] = []
    row = 0
    while row < len(lines):
        if row in replaced:
            last, new_text = replaced[row]
            out.append(new_text)
            row = last + 1
        else:
            out.append(lines[row])
            row += 1
    return "\n".join(out)


def _statements(body: list[ast.stmt]) -> list[ast.stmt]:
    out: list[ast.stmt] = []
    for node in body:
        out.append(node)
        for field in ("body", "orelse", "finalbody"):
            inner = getattr(node, field, None)
            if isinstance(inner, list):
                out += _statements([s for s in inner if isinstance(s, ast.stmt)])
        for handler in getattr(node, "handlers", []):
            out += _statements(handler.body)
    return out


def _rows_with_comments_or_long_strings(text: str) -> set[int]:
    rows: set[int] = set()
    for tok in tokenize.generate_tokens(io.StringIO(text).readline):
        if tok.type == tokenize.COMMENT or (tok.type == tokenize.STRING and tok.start[0] != tok.end[0]):
            rows.update(range(tok.start[0] - 1, tok.end[0]))
    return rows


def _is_docstring(node: ast.stmt) -> bool:
    return isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant) and isinstance(node.value.value, str)


def _layout_simple(statement: str, line_length: int, depth: int) -> str | None:
    tree = ast.parse(statement)
    node = tree.body[0]
    try:
        document = StatementLayout(Source(statement, node)).statement(node)
    except NotImplementedError:
        return None
    return Printer(line_length).print(document, depth)


def _layout_header(header: str, line_length: int, depth: int) -> str | None:
    keyword = header.split(" ", 1)[0]
    # parse "elif x:" as "if x:"; the body is irrelevant to the header
    offset = 2 if keyword == "elif" else 0
    parsed = ast.parse(header[offset:] + " pass").body[0]
    assert isinstance(parsed, ast.If | ast.While | ast.For)
    source_text = header[offset:] + " pass"
    try:
        document = StatementLayout(Source(source_text, parsed)).header(keyword, parsed)
    except NotImplementedError:
        return None
    return Printer(line_length).print(document, depth)

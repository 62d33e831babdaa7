"""Lays out the statements of a module: the entry point of the layout engine."""

from __future__ import annotations

import ast
import io
import keyword
import re
import tokenize

from .document import Element
from .printer import Printer, flat_text
from .source import Source, normalize_number, normalize_string, outside_fstrings
from .state import text_width
from .statements import StatementLayout

LINE_LENGTH = 120
_INDENT = 4
_SIMPLE = ast.Expr | ast.Assign | ast.AnnAssign | ast.AugAssign | ast.Return | ast.Raise | ast.ImportFrom
_HEADERS = ast.If | ast.While | ast.For
_DEFS = ast.FunctionDef | ast.AsyncFunctionDef
# what may need normalising on a line that fits: a string, a number, a comma that ends a
# collection (before a closing bracket, or after the one element of a tuple: a comma followed by
# anything that cannot start an expression)
_MAYBE_UNNORMALISED = re.compile(r"""['"]|(?<![\w.])\.?\d|,\s*(?:$|[^\s\w(\[{\-+~*.]|(?:in|if|else|for)\b)""")
_OPENING = re.compile(r"(\w*)\(")


def format_module(text: str, line_length: int = LINE_LENGTH) -> str:
    """``text`` with its statements laid out as ruff lays them out.

    Simple statements and the headers of ``if``/``elif``/``while``/``for`` are laid out afresh
    from their tokens (a statement written over several lines is first joined into one: only a
    trailing comma before a closing bracket keeps it broken, as in ruff); a statement with a
    comment or a triple-quoted string in it is kept as written.
    """
    lines = text.split("\n")
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
        elif isinstance(node, _DEFS):
            last = node.body[0].lineno - 2  # the header ends on the row before the body
            if last < first:
                continue
        else:
            continue
        rows = lines[first : last + 1]
        if _kept_as_written(rows):
            continue
        line = lines[first]
        depth, rest = divmod(len(line) - len(line.lstrip(" ")), _INDENT)
        if rest:
            continue
        simple_enough = not isinstance(node, _DEFS) and not (isinstance(node, ast.ImportFrom) and "(" in line)
        if first == last and len(line) <= line_length and simple_enough:
            if _plainly_written(line) or _as_written(node, line):
                continue
        try:
            if first == last:
                document = _document(node, Source(line, *_roots(node)), line)
            else:
                joined = " ".join(lines[row].strip() for row in range(first, last + 1))
                document = _joined_document(joined, node)
        except NotImplementedError:
            continue
        if document is not None:
            flat = flat_text(document)
            if flat is not None and _INDENT * depth + text_width(flat) <= line_length:
                replaced[first] = (last, " " * (_INDENT * depth) + flat)
            else:
                replaced[first] = (last, Printer(line_length).print(document, depth))
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


def _plainly_written(line: str) -> bool:
    """A quick test, on the text alone, that a line needs nothing :func:`_as_written` looks for: no
    literal to respell, no trailing comma, only call parentheses (after a name that is not a
    keyword, or after a closing bracket). Most lines pass it and need no walk over their AST."""
    if not line.isascii() or _MAYBE_UNNORMALISED.search(line):
        return False
    for match in _OPENING.finditer(line):
        name, at = match.group(1), match.start()
        if name:
            if keyword.iskeyword(name) or keyword.issoftkeyword(name):
                return False
        elif at == 0 or line[at - 1] not in ")]":
            return False
    return True


def _as_written(node: ast.stmt, line: str) -> bool:
    """Whether a statement that fits on its line is already as ruff writes it: literals spelled
    as ruff spells them (one part per string), no trailing comma that would keep brackets
    broken, no parentheses ruff drops. (Spacing between tokens is the emitters' business: they
    write it as ruff does, and the tests check generated/ with ruff.)"""
    if not line.isascii():
        return False  # AST offsets are in bytes: compare on ASCII lines only
    for expression in _top_expressions(node):
        if line[: expression.col_offset].rstrip().endswith("("):
            return False  # parentheses around a whole expression: ruff may drop them
    for sub in (n for root in _roots(node) for n in outside_fstrings(root)):
        if isinstance(sub, ast.Constant):
            text = line[sub.col_offset : sub.end_col_offset]
            if isinstance(sub.value, str | bytes):
                if normalize_string(text) != text:
                    return False  # other quotes, or parts ruff would join
            elif type(sub.value) in (int, float, complex) and normalize_number(text) != text:
                return False
        elif isinstance(sub, ast.JoinedStr):
            text = line[sub.col_offset : sub.end_col_offset]
            if normalize_string(text) != text:
                return False
        elif isinstance(sub, ast.Call | ast.List | ast.Set | ast.Dict | ast.Tuple | ast.Subscript):
            if isinstance(sub, ast.Tuple) and len(sub.elts) == 1:
                if line[sub.col_offset : sub.col_offset + 1] != "(":
                    return False  # ruff writes a one-element tuple in parentheses
                continue
            end = sub.end_col_offset or 0
            if line[end - 1 : end] in (")", "]", "}") and line[: end - 1].rstrip().endswith(","):
                return False  # a trailing comma keeps the brackets broken
    return True


def _top_expressions(node: ast.stmt) -> list[ast.expr]:
    """The expressions a statement holds directly (where ruff drops redundant parentheses)."""
    if isinstance(node, ast.For):
        return [node.target, node.iter]
    if isinstance(node, ast.If | ast.While):
        return [node.test]
    if isinstance(node, ast.Expr | ast.Return | ast.Assign | ast.AnnAssign | ast.AugAssign):
        value = [node.value] if node.value is not None else []
        if isinstance(node, ast.Assign):
            return [*node.targets, *value]
        if isinstance(node, ast.AnnAssign | ast.AugAssign):
            return [node.target, *value]
        return value
    if isinstance(node, ast.Raise):
        return [e for e in (node.exc, node.cause) if e is not None]
    return []


def _kept_as_written(rows: list[str]) -> bool:
    """Whether the rows of a statement hold a comment or a string written over several lines."""
    if not any("#" in row or '"""' in row or "'''" in row for row in rows):
        return False
    text = "\n".join([rows[0].lstrip(" "), *rows[1:]])
    try:
        for tok in tokenize.generate_tokens(io.StringIO(text).readline):
            if tok.type == tokenize.COMMENT or (tok.type == tokenize.STRING and tok.start[0] != tok.end[0]):
                return True
    except (tokenize.TokenError, SyntaxError):
        return True
    return False


def _roots(node: ast.stmt) -> list[ast.AST]:
    """The parts of the statement laid out: all of it, or a header's expressions."""
    if isinstance(node, _DEFS):
        return [node.args] + ([node.returns] if node.returns is not None else [])
    if isinstance(node, ast.For):
        return [node.target, node.iter]
    if isinstance(node, ast.If | ast.While):
        return [node.test]
    return [node]


def _document(node: ast.stmt, source: Source, line: str) -> list[Element] | None:
    layout = StatementLayout(source)
    if isinstance(node, _DEFS):
        return layout.function_header(node) if line.rstrip().endswith(":") else None
    if isinstance(node, _HEADERS):
        if not line.rstrip().endswith(":"):
            return None
        keyword = line.split()[0]
        return layout.header(keyword, node)
    return layout.statement(node)


def _joined_document(joined: str, original: ast.stmt) -> list[Element] | None:
    """The document of a statement written over several lines, joined into ``joined``."""
    if isinstance(original, _HEADERS | _DEFS):
        if not joined.endswith(":"):
            return None
        keyword = joined.split(" ", 1)[0]
        offset = 2 if keyword == "elif" else 0  # "elif x:" parses as "if x:"
        text = joined[offset:] + " pass"
        node = ast.parse(text).body[0]
        layout = StatementLayout(Source(text, *_roots(node)))
        if isinstance(node, _DEFS):
            return layout.function_header(node)
        assert isinstance(node, ast.If | ast.While | ast.For)
        return layout.header(keyword, node)
    node = ast.parse(joined).body[0]
    return StatementLayout(Source(joined, node)).statement(node)


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


def _is_docstring(node: ast.stmt) -> bool:
    return isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant) and isinstance(node.value.value, str)

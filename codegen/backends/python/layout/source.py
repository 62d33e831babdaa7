"""The source text of one statement (or one expression) next to its AST: what the AST forgets.

Parentheses written around an expression, the tokens of an implicitly concatenated string, a
trailing comma before a closing bracket and the spelling of literals come from the tokens; the
literal spellings are normalised here the way ruff normalises them (double quotes unless that
needs more escapes, upper-case hex digits, lower-case exponent).
"""

from __future__ import annotations

import ast
import io
import token as token_types
import tokenize
from dataclasses import dataclass

_SKIPPED = {token_types.NEWLINE, token_types.NL, token_types.ENDMARKER, token_types.INDENT, token_types.DEDENT}
_FSTRING_START = getattr(token_types, "FSTRING_START", -1)  # Python 3.12+ splits f-strings
_FSTRING_END = getattr(token_types, "FSTRING_END", -1)


@dataclass(frozen=True)
class Token:
    kind: int
    text: str
    start: int  # character offsets in the statement's single line
    end: int


def line_tokens(text: str) -> list[Token]:
    """The tokens of a one-line statement that matter here (an f-string as one STRING token)."""
    out: list[Token] = []
    fstring_start = 0  # column where the outermost open f-string starts
    depth = 0
    for tok in tokenize.generate_tokens(io.StringIO(text).readline):
        if tok.type in _SKIPPED or tok.type == token_types.COMMENT:
            continue
        if tok.start[0] != 1 or tok.end[0] != 1:
            raise NotImplementedError("a statement on one line was expected")
        if tok.type == _FSTRING_START:
            if depth == 0:
                fstring_start = tok.start[1]
            depth += 1
        elif depth:
            if tok.type == _FSTRING_END:
                depth -= 1
                if depth == 0:
                    end = tok.end[1]
                    out.append(Token(token_types.STRING, text[fstring_start:end], fstring_start, end))
        else:
            out.append(Token(tok.type, tok.string, tok.start[1], tok.end[1]))
    return out


class Source:
    """A one-line statement or expression: its tokens, and where each AST node sits among them."""

    def __init__(self, text: str, tokens: list[Token], *trees: ast.AST) -> None:
        self.text = text
        self.ascii = text.isascii()
        self.encoded = text.encode("utf-8")
        self.tokens = tokens
        self.by_start = {t.start: i for i, t in enumerate(self.tokens)}
        self.by_end = {t.end: i for i, t in enumerate(self.tokens)}
        self.match: dict[int, int] = {}
        opened: list[int] = []
        for i, t in enumerate(self.tokens):
            if t.text in ("(", "[", "{"):
                opened.append(i)
            elif t.text in (")", "]", "}"):
                j = opened.pop()
                self.match[i] = j
                self.match[j] = i
        # the parentheses of a call are its own, not parentheses around its (only) argument
        self.call_parens: set[int] = set()
        for node in (n for tree in trees for n in outside_fstrings(tree)):
            if isinstance(node, ast.Call):
                after = self.by_end[self.span(node.func)[1]] + 1
                while self.tokens[after].text == ")":  # the function itself in parentheses
                    after += 1
                self.call_parens.add(after)

    @classmethod
    def of_line(cls, text: str, *trees: ast.AST) -> Source:
        """A statement alone on one line (``text``, parsed into ``trees``)."""
        return cls(text, line_tokens(text), *trees)

    def char_offset(self, byte_offset: int) -> int:
        if self.ascii:
            return byte_offset
        return len(self.encoded[:byte_offset].decode("utf-8"))

    def span(self, node: ast.AST) -> tuple[int, int]:
        start = self.char_offset(getattr(node, "col_offset"))  # noqa: B009 - every expression has one
        end = self.char_offset(getattr(node, "end_col_offset"))  # noqa: B009
        return start, end

    def first_token(self, node: ast.AST) -> int:
        return self.by_start[self.span(node)[0]]

    def last_token(self, node: ast.AST) -> int:
        return self.by_end[self.span(node)[1]]

    def segment(self, node: ast.AST) -> str:
        start, end = self.span(node)
        return self.text[start:end]

    def is_parenthesized(self, node: ast.AST) -> bool:
        """Whether the source writes parentheses around the expression (its own ones excluded)."""
        before, after = self.first_token(node) - 1, self.last_token(node) + 1
        tokens = self.tokens
        return (
            before >= 0
            and after < len(tokens)
            and tokens[before].text == "("
            and tokens[after].text == ")"
            and self.match.get(before) == after
            and before not in self.call_parens
        )

    def own_parentheses(self, node: ast.Tuple | ast.GeneratorExp) -> bool:
        """A tuple or generator written with parentheses of its own (not a call's)."""
        first, last = self.first_token(node), self.last_token(node)
        return self.tokens[first].text == "(" and self.match.get(first) == last and first not in self.call_parens

    def magic_trailing_comma(self, closing: int) -> bool:
        return closing > 0 and self.tokens[closing - 1].text == ","

    def string_parts(self, node: ast.AST) -> list[str]:
        first, last = self.first_token(node), self.last_token(node)
        return [t.text for t in self.tokens[first : last + 1] if t.kind == token_types.STRING]


def outside_fstrings(tree: ast.AST) -> list[ast.AST]:
    """Every node but those inside f-strings (the tokens do not look inside an f-string)."""
    out: list[ast.AST] = []
    todo = [tree]
    while todo:
        node = todo.pop()
        out.append(node)
        if not isinstance(node, ast.JoinedStr):
            todo.extend(ast.iter_child_nodes(node))
    return out


# -- literal spellings ---------------------------------------------------------------------------


def normalize_number(text: str) -> str:
    """``0x7ff`` -> ``0x7FF``, ``1E5`` -> ``1e5``, ``1e+05`` -> ``1e05``; other spellings unchanged."""
    lower = text.lower()
    if lower.startswith(("0x", "0o", "0b")):
        return lower[:2] + (text[2:].upper() if lower.startswith("0x") else lower[2:])
    if lower.endswith("j"):
        return normalize_number(text[:-1]) + "j"
    out = lower.replace("e+", "e")
    if out.startswith("."):
        out = "0" + out
    if out.endswith("."):
        out += "0"
    return out.replace(".e", ".0e")


def _split_string(text: str) -> tuple[str, str, str] | None:
    """(prefix, quote, content) of a one-line, non-raw string token; None for others."""
    prefix = ""
    for ch in text:
        if ch in "'\"":
            break
        prefix += ch
    rest = text[len(prefix) :]
    if "r" in prefix.lower() or rest[:3] in ('"""', "'''"):
        return None
    return prefix, rest[0], rest[1:-1]


def choose_quote(contents: list[str]) -> str:
    """Double quotes, unless the text holds more double than single quotes."""
    singles = sum(c.count("'") for c in contents)
    doubles = sum(c.count('"') for c in contents)
    return "'" if singles < doubles else '"'


def requote(content: str, quote: str) -> str:
    """String content re-escaped for the delimiter ``quote``."""
    opposite = "'" if quote == '"' else '"'
    out: list[str] = []
    i, n = 0, len(content)
    while i < n:
        ch = content[i]
        if ch == "\\" and i + 1 < n:
            nxt = content[i + 1]
            if nxt == opposite:
                out.append(nxt)  # \' needs no backslash between double quotes
            elif nxt == "x" and i + 4 <= n:
                out.append("\\x" + content[i + 2 : i + 4].lower())
                i += 2
            else:
                out.append(ch + nxt)
            i += 2
            continue
        out.append("\\" + ch if ch == quote else ch)
        i += 1
    return "".join(out)


def normalize_string(text: str) -> str:
    parts = _split_string(text)
    if parts is None:
        return text
    prefix, quote, content = parts
    if "f" in prefix.lower():
        # an f-string keeps its quotes when any sit inside it (they may be in a replacement field)
        if "'" in content or '"' in content or "\\" in content:
            return text
        return f'{prefix}"{content}"'
    if not any(c in content for c in "'\"\\"):
        return f'{prefix}"{content}"'
    new = choose_quote([content])
    if new == quote:
        return prefix + quote + requote(content, quote) + quote
    return prefix + new + requote(content, new) + new


def joined_strings(parts: list[str]) -> str | None:
    """The implicitly concatenated ``parts`` as one literal, or None when they cannot be joined."""
    split = [_split_string(p) for p in parts]
    if any(s is None for s in split):
        return None
    prefixes = {s[0].lower() for s in split if s is not None}
    if len(prefixes) != 1 or "f" in next(iter(prefixes)):
        return None
    contents = [s[2] for s in split if s is not None]
    quote = choose_quote(contents)
    prefix = next(iter(prefixes))
    return prefix + quote + "".join(requote(c, quote) for c in contents) + quote

"""The source text of one statement (or one expression) next to its AST: what the AST forgets.

Parentheses written around an expression, the parts of an implicitly concatenated string, a
trailing comma before a closing bracket and the spelling of literals come from the text; the
literal spellings are normalised here the way ruff normalises them (double quotes unless that
needs more escapes, upper-case hex digits, lower-case exponent).
"""

from __future__ import annotations

import ast


def outside_fstrings(tree: ast.AST) -> list[ast.AST]:
    """Every node but those inside f-strings (their positions are not the source's in every Python)."""
    out: list[ast.AST] = []
    todo = [tree]
    while todo:
        node = todo.pop()
        out.append(node)
        if not isinstance(node, ast.JoinedStr):
            todo.extend(ast.iter_child_nodes(node))
    return out


class Source:
    """A statement or expression on one line: where each AST node sits in the text, which brackets
    match, which parentheses are a call's own. String literals are known from the AST, so the
    brackets are found by one scan of the text around them."""

    def __init__(self, text: str, *trees: ast.AST) -> None:
        self.text = text
        self.ascii = text.isascii()
        self.encoded = text.encode("utf-8")
        nodes = [n for tree in trees for n in outside_fstrings(tree)]
        strings = sorted(
            self.span(n)
            for n in nodes
            if isinstance(n, ast.JoinedStr) or (isinstance(n, ast.Constant) and isinstance(n.value, str | bytes))
        )
        self.match: dict[int, int] = {}
        opened: list[int] = []
        i, n, k = 0, len(text), 0
        while i < n:
            if k < len(strings) and i == strings[k][0]:
                i = strings[k][1]
                k += 1
                continue
            ch = text[i]
            if ch in "([{":
                opened.append(i)
            elif ch in ")]}":
                j = opened.pop()
                self.match[i], self.match[j] = j, i
            i += 1
        # the parentheses of a call are its own, not parentheses around its (only) argument
        self.call_parens: set[int] = set()
        for node in nodes:
            if isinstance(node, ast.Call):
                at = self.span(node.func)[1]
                while text[at] in " )":  # the function itself may be in parentheses
                    at += 1
                self.call_parens.add(at)

    def char_offset(self, byte_offset: int) -> int:
        if self.ascii:
            return byte_offset
        return len(self.encoded[:byte_offset].decode("utf-8"))

    def span(self, node: ast.AST) -> tuple[int, int]:
        start = self.char_offset(getattr(node, "col_offset"))  # noqa: B009 - every expression has one
        end = self.char_offset(getattr(node, "end_col_offset"))  # noqa: B009
        return start, end

    def segment(self, node: ast.AST) -> str:
        start, end = self.span(node)
        return self.text[start:end]

    def _before(self, at: int) -> int:
        at -= 1
        while at >= 0 and self.text[at] == " ":
            at -= 1
        return at

    def _after(self, at: int) -> int:
        while at < len(self.text) and self.text[at] == " ":
            at += 1
        return at

    def is_parenthesized(self, node: ast.AST) -> bool:
        """Whether the source writes parentheses around the expression (its own ones excluded)."""
        start, end = self.span(node)
        before, after = self._before(start), self._after(end)
        return (
            before >= 0
            and self.text[before] == "("
            and self.match.get(before) == after
            and before not in self.call_parens
        )

    def own_parentheses(self, node: ast.Tuple | ast.GeneratorExp) -> bool:
        """A tuple or generator written with parentheses of its own (not a call's)."""
        start, end = self.span(node)
        return self.text[start] == "(" and self.match.get(start) == end - 1 and start not in self.call_parens

    def magic_trailing_comma(self, node: ast.AST) -> bool:
        """Whether a comma precedes the bracket that closes ``node``."""
        closing = self.span(node)[1] - 1
        before = self._before(closing)
        return before >= 0 and self.text[before] == ","

    def string_parts(self, node: ast.AST) -> list[str]:
        """The string literals an (implicitly concatenated) string expression is written as."""
        text, (at, end) = self.text, self.span(node)
        parts: list[str] = []
        while at < end:
            start = at
            while text[at] not in "'\"":
                at += 1
            quote = text[at : at + 3] if text[at : at + 3] in ('"""', "'''") else text[at]
            at += len(quote)
            while text[at : at + len(quote)] != quote:
                at += 2 if text[at] == "\\" else 1
            at += len(quote)
            parts.append(text[start:at])
            at = self._after(at)
        return parts


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

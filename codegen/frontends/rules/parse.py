"""The rule expression parser: text -> the AST of :mod:`codegen.ir.expr` (a tokenizer and a recursive-descent parser).

The grammar::

    expr     := or
    or       := and ("or" and)*
    and      := not ("and" not)*
    not      := "not" not | compare
    compare  := sum (("<" | "<=" | ">" | ">=" | "==" | "!=" | "in" | "not in") sum)*   (chains like Python)
    sum      := term (("+" | "-") term)*
    term     := unary (("*" | "/" | "//" | "%") unary)*
    unary    := ("-" | "+") unary | postfix
    postfix  := primary ("[" expr "]")*
    primary  := NUMBER | STRING | "true" | "false" | NAME | `schema name` | "(" expr ")"
              | "[" [expr ("," expr)*] "]" | FUNC "(" args ")" | ("all" | "any") "(" expr "for" NAME "in" expr ")"

Names are fields of the message (schema spelling; a name that is not an identifier, such as
``voltage-min-design-microvolt`` or a pattern property, is written in backquotes), loop variables
bound by a rule's ``for``, and the message's constants; the parser leaves every one a
:class:`~codegen.ir.expr.Name`. Functions: see :data:`~codegen.ir.expr.FUNCTIONS`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from ...ir.expr import (
    FUNCTIONS,
    Binary,
    BoolOp,
    Call,
    Compare,
    Const,
    Expr,
    Index,
    ListLit,
    Loop,
    Name,
    Not,
    Quant,
    Template,
    Unary,
)

KEYWORDS = frozenset({"and", "or", "not", "in", "for", "true", "false"})


class ExprError(Exception):
    """A malformed expression; ``column`` is 1-based within the expression text."""

    def __init__(self, message: str, column: int) -> None:
        super().__init__(message)
        self.message = message
        self.column = column


# --------------------------------------------------------------------------------------------
# Tokens

_TOKEN = re.compile(
    r"""
    (?P<space>\s+)
  | (?P<number>0[xX][0-9a-fA-F]+|(?:\d+\.\d*|\.\d+|\d+)(?:[eE][+-]?\d+)?)
  | (?P<string>"[^"\\\n]*"|'[^'\\\n]*')
  | (?P<quoted>`[^`\n]+`)
  | (?P<name>[A-Za-z_][A-Za-z0-9_]*)
  | (?P<op>//|<=|>=|==|!=|[-+*/%<>()\[\],])
    """,
    re.VERBOSE,
)


@dataclass(frozen=True)
class Token:
    kind: str  # number, string, quoted, name, op, end
    text: str
    column: int


def tokenize(text: str) -> list[Token]:
    tokens: list[Token] = []
    pos = 0
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if m is None:
            raise ExprError(f"unexpected character {text[pos]!r}", pos + 1)
        kind = m.lastgroup or ""
        if kind != "space":
            tokens.append(Token(kind, m.group(), pos + 1))
        pos = m.end()
    tokens.append(Token("end", "", len(text) + 1))
    return tokens


# --------------------------------------------------------------------------------------------
# Parser

_COMPARE_OPS = ("<", "<=", ">", ">=", "==", "!=")


class _Parser:
    def __init__(self, text: str) -> None:
        self.tokens = tokenize(text)
        self.pos = 0

    @property
    def tok(self) -> Token:
        return self.tokens[self.pos]

    def peek(self, offset: int = 1) -> Token:
        return self.tokens[min(self.pos + offset, len(self.tokens) - 1)]

    def at(self, text: str) -> bool:
        t = self.tok
        return t.kind in ("op", "name") and t.text == text

    def take(self) -> Token:
        t = self.tok
        self.pos += 1
        return t

    def expect(self, text: str, what: str) -> Token:
        if not self.at(text):
            raise ExprError(f"expected {what}, found {self.describe(self.tok)}", self.tok.column)
        return self.take()

    @staticmethod
    def describe(t: Token) -> str:
        return "the end of the expression" if t.kind == "end" else repr(t.text)

    def parse(self) -> Expr:
        expr = self.expr()
        if self.tok.kind != "end":
            raise ExprError(f"unexpected {self.describe(self.tok)} after a complete expression", self.tok.column)
        return expr

    def expr(self) -> Expr:
        return self.or_()

    def or_(self) -> Expr:
        values = [self.and_()]
        while self.at("or"):
            self.take()
            values.append(self.and_())
        return values[0] if len(values) == 1 else BoolOp("or", tuple(values))

    def and_(self) -> Expr:
        values = [self.not_()]
        while self.at("and"):
            self.take()
            values.append(self.not_())
        return values[0] if len(values) == 1 else BoolOp("and", tuple(values))

    def not_(self) -> Expr:
        if self.at("not"):
            self.take()
            return Not(self.not_())
        return self.compare()

    def compare_op(self) -> str | None:
        t = self.tok
        if t.kind == "op" and t.text in _COMPARE_OPS:
            return t.text
        if t.kind == "name" and t.text == "in":
            return "in"
        if t.kind == "name" and t.text == "not" and self.peek().kind == "name" and self.peek().text == "in":
            return "not in"
        return None

    def compare(self) -> Expr:
        operands = [self.sum()]
        ops: list[str] = []
        while (op := self.compare_op()) is not None:
            self.take()
            if op == "not in":
                self.take()
            ops.append(op)
            operands.append(self.sum())
        return operands[0] if not ops else Compare(tuple(ops), tuple(operands))

    def sum(self) -> Expr:
        left = self.term()
        while self.tok.kind == "op" and self.tok.text in ("+", "-"):
            op = self.take().text
            left = Binary(op, left, self.term())
        return left

    def term(self) -> Expr:
        left = self.unary()
        while self.tok.kind == "op" and self.tok.text in ("*", "/", "//", "%"):
            op = self.take().text
            left = Binary(op, left, self.unary())
        return left

    def unary(self) -> Expr:
        if self.tok.kind == "op" and self.tok.text in ("-", "+"):
            op = self.take().text
            return Unary(op, self.unary())
        return self.postfix()

    def postfix(self) -> Expr:
        expr = self.primary()
        while self.at("["):
            self.take()
            index = self.expr()
            self.expect("]", "']' closing the index")
            expr = Index(expr, index)
        return expr

    def primary(self) -> Expr:
        t = self.tok
        if t.kind == "number":
            self.take()
            text = t.text
            if text[:2] in ("0x", "0X"):
                return Const(int(text, 16))
            return Const(float(text) if any(c in text for c in ".eE") else int(text))
        if t.kind == "string":
            self.take()
            return Const(t.text[1:-1])
        if t.kind == "quoted":
            self.take()
            return Name(t.text[1:-1], True, t.column)
        if t.kind == "op" and t.text == "(":
            self.take()
            inner = self.expr()
            self.expect(")", "')'")
            return inner
        if t.kind == "op" and t.text == "[":
            self.take()
            items: list[Expr] = []
            if not self.at("]"):
                items.append(self.expr())
                while self.at(","):
                    self.take()
                    items.append(self.expr())
            self.expect("]", "']' closing the list")
            return ListLit(tuple(items))
        if t.kind == "name":
            if t.text in ("true", "false"):
                self.take()
                return Const(t.text == "true")
            if t.text in KEYWORDS:
                raise ExprError(f"expected a value, found the keyword {t.text!r}", t.column)
            if self.peek().kind == "op" and self.peek().text == "(":
                return self.call()
            self.take()
            return Name(t.text, False, t.column)
        raise ExprError(f"expected a value, found {self.describe(t)}", t.column)

    def call(self) -> Expr:
        name = self.take()
        if name.text not in FUNCTIONS:
            known = ", ".join(sorted(FUNCTIONS))
            raise ExprError(f"unknown function {name.text!r} (known: {known})", name.column)
        self.expect("(", "'('")
        args: list[Expr] = []
        if not self.at(")"):
            args.append(self.expr())
            if name.text in ("all", "any") and self.at("for"):
                self.take()
                var = self.tok
                if var.kind != "name" or var.text in KEYWORDS:
                    raise ExprError(f"expected a loop variable name, found {self.describe(var)}", var.column)
                self.take()
                self.expect("in", "'in'")
                iterable = self.expr()
                self.expect(")", "')' closing the generator")
                return Quant(name.text, args[0], var.text, iterable)
            while self.at(","):
                self.take()
                args.append(self.expr())
        self.expect(")", f"')' closing {name.text}(")
        low, high = FUNCTIONS[name.text]
        if len(args) < low or (high is not None and len(args) > high):
            count = str(low) if low == high else f"{low}.." + ("" if high is None else str(high))
            raise ExprError(f"{name.text}() takes {count} argument(s), got {len(args)}", name.column)
        return Call(name.text, tuple(args), name.column)


def parse(text: str) -> Expr:
    """Parse one rule expression; raises :class:`ExprError` with the column of the problem."""
    return _Parser(text).parse()


def parse_binding(text: str) -> Loop:
    """A ``for`` binding: ``NAME in EXPR``."""
    p = _Parser(text)
    var = p.tok
    if var.kind != "name" or var.text in KEYWORDS or var.text in FUNCTIONS:
        raise ExprError(f"expected a loop variable name, found {p.describe(var)}", var.column)
    p.take()
    p.expect("in", "'in' after the loop variable")
    return Loop(var.text, p.parse())


def parse_template(text: str) -> Template:
    """A message template: text with ``{expr}`` placeholders (``{{`` and ``}}`` stand for braces)."""
    parts: list[str | Expr] = []
    buf: list[str] = []
    i = 0
    while i < len(text):
        ch = text[i]
        if ch in "{}" and text[i + 1 : i + 2] == ch:
            buf.append(ch)
            i += 2
            continue
        if ch == "}":
            raise ExprError("'}' without a matching '{' (write '}}' for a brace)", i + 1)
        if ch == "{":
            end = text.find("}", i + 1)
            if end < 0:
                raise ExprError("'{' without a matching '}' (write '{{' for a brace)", i + 1)
            if buf:
                parts.append("".join(buf))
                buf = []
            try:
                parts.append(parse(text[i + 1 : end]))
            except ExprError as exc:
                raise ExprError(exc.message, i + 1 + exc.column) from None
            i = end + 1
            continue
        buf.append(ch)
        i += 1
    if buf:
        parts.append("".join(buf))
    return tuple(parts)

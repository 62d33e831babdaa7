"""Safe evaluation of DSDL v0 constant initialisers.

DSDL v0 initialisers are Python-flavoured expressions (the reference tool hands them to Python).
We accept the arithmetic subset the format needs and nothing else: int/float/bool literals,
``true``/``false``, one-character literals ('a'), parentheses and + - * / // % ** << >> & | ^ ~.
The expression is walked as an AST over an allow-list, so names, calls, attributes, subscripts
and the like are rejected before anything runs. ``/`` is true division, as in the reference.
"""

from __future__ import annotations

import ast
import math
import operator
import warnings
from collections.abc import Callable

Number = int | float

EXPECTED = (
    "a constant expression of numbers, 'c' character literals, true/false, parentheses "
    "and + - * / // % ** << >> & | ^ ~"
)

_MAX_INT_BITS = 4096  # far above any DSDL width; stops 2**10**9 style blow-ups
_MAX_SHIFT = 4096

_BINARY: dict[type[ast.operator], Callable[[Number, Number], Number]] = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.FloorDiv: operator.floordiv,
    ast.Mod: operator.mod,
    ast.Pow: operator.pow,
}
_BITWISE: dict[type[ast.operator], Callable[[int, int], int]] = {
    ast.LShift: operator.lshift,
    ast.RShift: operator.rshift,
    ast.BitAnd: operator.and_,
    ast.BitOr: operator.or_,
    ast.BitXor: operator.xor,
}
_NAMES: dict[str, int] = {"true": 1, "false": 0}


class ExpressionError(ValueError):
    """The initialiser is not an allowed constant expression; the text says what is wrong."""


def evaluate(text: str) -> int | float | str:
    """Evaluate an initialiser: a number, or a one-character string for a char literal."""
    try:
        with warnings.catch_warnings():  # e.g. "invalid decimal literal" for 1if1else2
            warnings.simplefilter("ignore")
            tree = ast.parse(text, mode="eval")
    except (SyntaxError, ValueError, RecursionError, MemoryError):
        raise ExpressionError(f"expected {EXPECTED}, got {text!r}") from None
    body = tree.body
    if isinstance(body, ast.Constant) and isinstance(body.value, str):
        if len(body.value) != 1:
            raise ExpressionError(f"expected a one-character literal, got {body.value!r}")
        return body.value
    try:
        return _number(body)
    except RecursionError:
        raise ExpressionError("expected a less deeply nested expression") from None


def _number(node: ast.expr) -> Number:
    if isinstance(node, ast.Constant):
        value = node.value
        if isinstance(value, bool):
            return int(value)
        if isinstance(value, int | float):
            return value
        if isinstance(value, str) and len(value) == 1:
            return ord(value)
        raise ExpressionError(f"expected a number or a one-character literal, got {value!r}")
    if isinstance(node, ast.Name):
        if node.id in _NAMES:
            return _NAMES[node.id]
        raise ExpressionError(f"expected a literal, true or false; names like {node.id!r} are not allowed")
    if isinstance(node, ast.UnaryOp):
        operand = _number(node.operand)
        if isinstance(node.op, ast.USub):
            return -operand
        if isinstance(node.op, ast.UAdd):
            return +operand
        if isinstance(node.op, ast.Invert) and isinstance(operand, int):
            return ~operand
        raise ExpressionError("expected ~ on an integer, or unary + / -")
    if isinstance(node, ast.BinOp):
        return _binary(node)
    raise ExpressionError(f"expected {EXPECTED}; {type(node).__name__} is not allowed")


def _binary(node: ast.BinOp) -> Number:
    left, right = _number(node.left), _number(node.right)
    op = type(node.op)
    try:
        if op in _BITWISE:
            if not (isinstance(left, int) and isinstance(right, int)):
                raise ExpressionError("expected integers on both sides of a bitwise operator")
            if op in (ast.LShift, ast.RShift) and not 0 <= right <= _MAX_SHIFT:
                raise ExpressionError(f"expected a shift count within 0..{_MAX_SHIFT}, got {right}")
            result: Number = _BITWISE[op](left, right)
        elif op in _BINARY:
            if op is ast.Pow and isinstance(left, int) and isinstance(right, int) and left not in (-1, 0, 1):
                if right > _MAX_INT_BITS:
                    raise ExpressionError(f"expected a smaller exponent than {right}")
            result = _BINARY[op](left, right)
        else:
            raise ExpressionError(f"expected {EXPECTED}; operator {op.__name__} is not allowed")
    except (ZeroDivisionError, OverflowError) as exc:
        raise ExpressionError(f"expected a computable value: {exc}") from None
    if isinstance(result, int) and result.bit_length() > _MAX_INT_BITS:
        raise ExpressionError("expected a value that fits 4096 bits")
    if isinstance(result, complex) or (isinstance(result, float) and math.isnan(result)):
        raise ExpressionError("expected a real number")
    return result

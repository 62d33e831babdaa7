"""Cross-field rules (``Schema.rules`` bound to a message) as Rust methods of the message, run by its
``validate_into`` after the field checks, as ``codegen/backends/python/validators/rules.py`` compiles them
into Python: the rule's ``where`` guard, its ``for i in range(a, b)`` loop (kept to the message's largest
array, as the Python ``_v.span``), its check, and a problem (the field its ``path`` names, the element, the
rule id) when the check fails. Values are read as Python compares them: integers in i128 (every wire
integer fits), floats in f64, an integer compared with a float exactly (``support/rules.rs``:
``int_float``). Where Python would raise (an index beyond the array, a division by zero,
an overflow) the rule reports nothing, as the Python ``except _v.SLOW`` does: each method returns
``Option`` and stops at ``?``. A rule using what this module does not spell (text, ``in``,
``all``/``any``, floor division, nested loops) is left out of the crate; :class:`RustRules` says which."""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from ...ir import ArrayType, Field, Message, PrimitiveKind, PrimitiveType, Schema
from ...ir.expr import Binary, BoolOp, Call, Compare, Const, Expr, FieldRef, Index, Not, Unary, VarRef, children
from ...ir.rules import BoundRule, bound_rules
from .naming import field_ident
from .types import equals, float_literal, scalar

_OPS = {"<", "<=", ">", ">=", "==", "!="}
_CHECKED = {"+": "checked_add", "-": "checked_sub", "*": "checked_mul"}
# the bound of range() over unbounded arrays, as the Python runtime's _validate.SPAN_LIMIT
_SPAN_LIMIT = 1 << 16


class Unsupported(Exception):
    """A rule the Rust validators do not spell yet: it is left out of the crate."""


@dataclass(frozen=True)
class _Value:
    code: str
    kind: str  # "int" (i128), "float" (f64), "bool"
    const: int | float | bool | None = None


@dataclass
class RustRules:
    """The rules of one message: methods of its ``impl``, the calls ``validate_into`` makes, how many
    problems they can report at most, and the rules left out with why."""

    methods: list[str] = field(default_factory=list)
    calls: list[str] = field(default_factory=list)
    most: int = 0
    left: list[str] = field(default_factory=list)


def _strip(code: str) -> str:
    """``code`` without one pair of parentheses around all of it (rustc warns of them in a let or an argument)."""
    if not (code.startswith("(") and code.endswith(")")):
        return code
    depth = 0
    for n, ch in enumerate(code):
        depth += {"(": 1, ")": -1}.get(ch, 0)
        if depth == 0 and n < len(code) - 1:
            return code
    return code[1:-1]


def _float(v: _Value) -> str:
    if v.kind == "float":
        return v.code
    if v.kind != "int":
        raise Unsupported("a truth value in arithmetic")
    if v.const is not None:
        return float_literal(float(v.const), "f64")
    return f"({v.code} as f64)"


# an integer Python compares with a float exactly; one of at most 2^53 is exact as an f64 too
_EXACT = 1 << 53
_ORDER = {
    "<": "Some(Ordering::Less)",
    "<=": "Some(Ordering::Less | Ordering::Equal)",
    ">": "Some(Ordering::Greater)",
    ">=": "Some(Ordering::Greater | Ordering::Equal)",
    "==": "Some(Ordering::Equal)",
    "!=": "Some(Ordering::Equal)",
}


def _pair(a: _Value, op: str, b: _Value) -> str:
    """``a op b`` as Python compares them: an integer with a float exactly (not rounded to an f64;
    NaN unordered), unless the integer is a constant an f64 holds exactly."""
    if a.kind == b.kind:
        return f"{a.code} {op} {b.code}"
    small = [v for v in (a, b) if v.kind == "int" and v.const is not None and abs(int(v.const)) <= _EXACT]
    if small:
        return f"{_float(a)} {op} {_float(b)}"
    order = (
        f"crate::rules::int_float({_strip(a.code)}, {_strip(b.code)})"
        if a.kind == "int"
        else f"crate::rules::float_int({_strip(a.code)}, {_strip(b.code)})"
    )
    test = f"matches!({order}, {_ORDER[op].replace('Ordering::', 'core::cmp::Ordering::')})"
    return f"!{test}" if op == "!=" else test


class _Rule:
    def __init__(self, msg: Message) -> None:
        self.fields = {f.name: f for f in msg.fields if not f.is_padding}
        caps = [f.type.capacity for f in msg.fields if isinstance(f.type, ArrayType)]
        self.limit = _SPAN_LIMIT if None in caps else max((c or 0 for c in caps), default=0)

    def field(self, name: str) -> tuple[Field, PrimitiveType]:
        f = self.fields[name]
        t = f.type
        if isinstance(t, ArrayType):
            t = t.element
        if not isinstance(t, PrimitiveType) or t.kind in (PrimitiveKind.CHAR, PrimitiveKind.VOID):
            raise Unsupported(f"{name}: not a number")
        if f.pattern is not None:
            raise Unsupported(f"{name}: a pattern of fields")
        return f, t

    def read(self, t: PrimitiveType, code: str) -> _Value:
        rust = scalar(t)
        if rust == "bool":
            return _Value(code, "bool")
        if rust == "f64":
            return _Value(code, "float")
        return _Value(f"f64::from({code})", "float") if rust == "f32" else _Value(f"i128::from({code})", "int")

    def slice(self, f: Field) -> str:
        t = f.type
        assert isinstance(t, ArrayType)
        ident = field_ident(f.name)
        return f"&self.{ident}[..self.{ident}_len.min({t.capacity or 1})]" if t.dynamic else f"&self.{ident}"

    def length(self, f: Field) -> str:
        t = f.type
        assert isinstance(t, ArrayType)
        return f"(self.{field_ident(f.name)}_len as i128)" if t.dynamic else str(t.capacity or 0)

    def expr(self, e: Expr) -> _Value:
        if isinstance(e, Const):
            if isinstance(e.value, bool):
                return _Value("true" if e.value else "false", "bool", e.value)
            if isinstance(e.value, int):
                return _Value(str(e.value) if e.value >= 0 else f"({e.value})", "int", e.value)
            if isinstance(e.value, float):
                return _Value(float_literal(e.value, "f64"), "float", e.value)
            raise Unsupported("text")
        if isinstance(e, FieldRef):
            f, t = self.field(e.name)
            if isinstance(f.type, ArrayType):
                raise Unsupported(f"{e.name}: a whole array")
            return self.read(t, f"self.{field_ident(e.name)}")
        if isinstance(e, VarRef):
            return _Value(f"v_{e.name}", "int")
        if isinstance(e, Unary):
            v = self.expr(e.operand)
            if v.kind == "bool":
                raise Unsupported("a sign on a truth value")
            return _Value(f"({e.op}{v.code})", v.kind)
        if isinstance(e, Binary):
            return self.binary(e)
        if isinstance(e, Compare):
            return self.compare(e)
        if isinstance(e, BoolOp):
            parts = [self.expr(x) for x in e.values]
            if any(p.kind != "bool" for p in parts):
                raise Unsupported("and/or over values that are not truth values")
            return _Value("(" + (" && " if e.op == "and" else " || ").join(p.code for p in parts) + ")", "bool")
        if isinstance(e, Not):
            v = self.expr(e.operand)
            if v.kind != "bool":
                raise Unsupported("not of a number")
            return _Value(f"(!{v.code})", "bool")
        if isinstance(e, Index):
            if not isinstance(e.target, FieldRef):
                raise Unsupported("an index into an expression")
            f, t = self.field(e.target.name)
            if not isinstance(f.type, ArrayType):
                raise Unsupported("an index into a scalar")
            i = self.expr(e.index)
            if i.kind != "int":
                raise Unsupported("an index that is not an integer")
            return self.read(t, f"crate::rules::at({self.slice(f)}, {_strip(i.code)})?")
        if isinstance(e, Call):
            return self.call(e)
        raise Unsupported(type(e).__name__)

    def binary(self, e: Binary) -> _Value:
        left, right = self.expr(e.left), self.expr(e.right)
        if e.op == "/":  # Python's true division; ZeroDivisionError -> None
            return _Value(f"crate::rules::div({_strip(_float(left))}, {_strip(_float(right))})?", "float")
        if e.op not in _CHECKED:
            raise Unsupported(f"the operator {e.op}")
        if left.kind == right.kind == "int":
            return _Value(f"i128::{_CHECKED[e.op]}({_strip(left.code)}, {_strip(right.code)})?", "int")
        return _Value(f"({_float(left)} {e.op} {_float(right)})", "float")

    def compare(self, e: Compare) -> _Value:
        if any(op not in _OPS for op in e.ops):
            raise Unsupported("membership")
        terms = [self.expr(x) for x in e.operands]
        if any(t.kind == "bool" for t in terms) and not all(t.kind == "bool" for t in terms):
            raise Unsupported("a truth value compared with a number")
        pairs = [_pair(a, op, b) for a, op, b in zip(terms[:-1], e.ops, terms[1:], strict=True)]
        return _Value("(" + " && ".join(pairs) + ")", "bool")

    def call(self, e: Call) -> _Value:
        if e.func == "len" and isinstance(e.args[0], FieldRef):
            f = self.fields[e.args[0].name]
            if not isinstance(f.type, ArrayType):
                raise Unsupported("len of a scalar")
            return _Value(self.length(f), "int")
        if e.func == "is_known" and isinstance(e.args[0], FieldRef):
            return _Value(self.known(e.args[0].name), "bool")
        if e.func == "abs":
            v = self.expr(e.args[0])
            if v.kind == "bool":
                raise Unsupported("abs of a truth value")
            rust = "i128" if v.kind == "int" else "f64"
            return _Value(f"{rust}::abs({_strip(v.code)})", v.kind)
        raise Unsupported(f"{e.func}()")

    def known(self, name: str) -> str:
        """The Python ``known_expr``: the field is not at its "unknown" sentinel."""
        f, t = self.field(name)
        s = f.invalid
        if s is None:
            return "true"
        ident = field_ident(name)
        if not isinstance(f.type, ArrayType):
            return "(" + equals(t, s.value, f"self.{ident}", negate=True) + ")"
        if s.elements:
            raise Unsupported("per-position markers")
        if s.first_decides:
            first = equals(t, s.value, f"self.{ident}[0]", negate=True)
            return f"({self.length(f)} > 0 && {first})"
        return f"{self.slice(f)}.iter().any(|&e| {equals(t, s.value, 'e', negate=True)})"


def _uses(e: Expr | None, var: str) -> bool:
    if e is None:
        return False
    return (isinstance(e, VarRef) and e.name == var) or any(_uses(c, var) for c in children(e))


def _place(r: _Rule, bound: BoundRule) -> tuple[str, str]:
    """(the field a problem names, its index as ``Option<usize>`` code)."""
    place = bound.path
    if place is None:
        named = [n for n in _fields(bound.check) if n in r.fields]
        if not named:
            raise Unsupported("no field to report")
        return named[0], "None"
    index = "None"
    if isinstance(place, Index):
        i = r.expr(place.index)
        if i.kind != "int":
            raise Unsupported("a path indexed by a value that is not an integer")
        index = f"crate::rules::position({_strip(i.code)})"
        place = place.target
    if not isinstance(place, FieldRef):
        raise Unsupported("a path that is not a field or one element of it")
    return place.name, index


def _fields(e: Expr) -> list[str]:
    if isinstance(e, FieldRef):
        return [e.name]
    return [n for c in children(e) for n in _fields(c)]


def _method_name(rule_id: str) -> str:
    return "rule_" + (re.sub(r"[^0-9a-z]+", "_", rule_id.lower()).strip("_") or "unnamed")


def _one(r: _Rule, bound: BoundRule, name: str) -> tuple[list[str], str, int]:
    """(the methods checking the rule, the call of ``validate_into``, how many problems at most)."""
    rule = bound.rule
    if len(bound.bindings) > 1:
        raise Unsupported("nested loops")
    check = r.expr(bound.check)
    if check.kind != "bool":
        raise Unsupported("a check that is not a truth value")
    where = r.expr(bound.where) if bound.where is not None else None
    if where is not None and where.kind != "bool":
        raise Unsupported("a where that is not a truth value")
    target, index = _place(r, bound)
    push = f'out.push("{target}", {index}, Rule::CrossField("{rule.id}"));'
    test = ["let holds = " + _strip(check.code) + ";", f"if !holds {{ {push} }}", "Some(())"]
    guard = [f"let applies = {_strip(where.code)};", "if !applies { return Some(()); }"] if where is not None else []
    head = [f"/// `{rule.id}` ({rule.location}): {' '.join(rule.doc.split()) or rule.check}"]
    sig = f"fn {name}<const N: usize>(&self, out: &mut Problems<N>"
    if not bound.bindings:
        return [*head, f"{sig}) -> Option<()> {{", *guard, *test, "}"], f"self.{name}(out);", 1
    var, iterable = bound.bindings[0]
    if not (isinstance(iterable, Call) and iterable.func == "range" and len(iterable.args) in (1, 2)):
        raise Unsupported("a loop not over range()")
    args = [r.expr(a) for a in iterable.args]
    if any(a.kind != "int" for a in args):
        raise Unsupported("range() of values that are not integers")
    start, stop = ("0", args[0].code) if len(args) == 1 else (args[0].code, args[1].code)
    used = _uses(bound.check, var) or _uses(bound.path, var)
    loop = [
        *head,
        f"{sig}) -> Option<()> {{",
        *guard,
        f"for v in crate::rules::span({_strip(start)}, {_strip(stop)}, {r.limit}) {{",
        f"self.{name}_at(out, v);",
        "}",
        "Some(())",
        "}",
    ]
    param = f"{'' if used else '_'}v_{var}: i128"
    each = [
        f"/// `{rule.id}` at one `{var}`.",
        f"fn {name}_at{sig[len('fn ') + len(name) :]}, {param}) -> Option<()> {{",
        *test,
        "}",
    ]
    return [*loop, *each], f"self.{name}(out);", r.limit


def rust_rules(schema: Schema, msg: Message) -> RustRules:
    """The cross-field rules of ``msg`` as methods of its Rust struct."""
    out = RustRules()
    taken: set[str] = set()
    for bound in bound_rules(schema, msg):
        name = _method_name(bound.rule.id)
        while name in taken:
            name += "_"
        try:
            methods, call, most = _one(_Rule(msg), bound, name)
        except Unsupported as why:
            out.left.append(f"{bound.rule.id} ({bound.rule.location}): {why}")
            continue
        taken.add(name)
        out.methods += methods
        out.calls.append(call)
        out.most += most
    return out

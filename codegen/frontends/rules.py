"""Cross-field rules: declarative YAML files in ``schemas/rules/``, read into the IR
(:class:`~codegen.ir.CrossFieldRule`, in ``Schema.rules``) and compiled by the validators into
each generated ``validate()``.

A rule file names the messages it applies to and lists rules; each rule has an ``assert``
expression (the language is in :mod:`codegen.ir.expr`), optional ``where`` precondition and
``for`` loops, a ``message`` template with ``{expr}`` placeholders and a severity (``warning`` for
advice). Files are checked against ``codegen/rules.schema.json`` and every expression is parsed at
load time; names are resolved against the message when the rules are compiled. Any problem is a
:class:`~codegen.errors.SchemaError` naming the file and line.

Semantics the compiled code keeps: a rule is skipped while a devicetree property it reads is
absent; a rule whose evaluation fails (an index out of range, a value of the wrong type) is skipped
too, since the field checks already report the cause.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any

import jsonschema

from ..errors import SchemaError
from ..ir import CrossFieldRule, Location, Message, Schema
from ..ir.expr import (
    Binary,
    BoolOp,
    Call,
    Compare,
    Const,
    Expr,
    ExprError,
    FieldRef,
    Index,
    ListLit,
    Name,
    Not,
    Quant,
    Unary,
    VarRef,
    parse,
    parse_binding,
    parse_template,
)
from ..text.files import display_path, read_text
from ..text.yaml_lines import YList, YMap, line_at
from ..text.yaml_lines import load as load_yaml

SEVERITIES = ("error", "warning")


@dataclass(frozen=True)
class Rule:
    """A parsed rule; expressions hold unresolved names until :func:`bind`."""

    id: str
    severity: str
    doc: str
    where: Expr | None
    bindings: tuple[tuple[str, Expr], ...]
    check: Expr
    path: Expr | None
    message: tuple[str | Expr, ...]
    text: str  # the assert as written: the violation's limit
    location: Location
    lines: tuple[tuple[str, int], ...]  # key -> line, for errors found when binding

    def line_of(self, key: str) -> int:
        return dict(self.lines).get(key, self.location.line)


# --------------------------------------------------------------------------------------------
# The rules of a schema


def bound_rules(schema: Schema, msg: Message) -> list[BoundRule]:
    """The schema's rules for ``msg``, parsed and bound to its fields (names it lacks are errors)."""
    return [bind(parsed(rule), msg) for rule in rules_for(schema.rules, msg.qualified_name)]


def check_rules(schema: Schema) -> None:
    """Every rule names loaded messages and binds to each; a message of a format that is not
    loaded at all is allowed (a rules folder may serve a subset of the schemas)."""
    loaded = {m.qualified_name: m for m in schema.messages}
    formats = {name.split(".", 1)[0] for name in loaded}
    for rule in schema.rules:
        for name in rule.messages:
            if name in loaded:
                bind(parsed(rule), loaded[name])
            elif name.split(".", 1)[0] in formats:
                raise SchemaError(
                    rule.location.file,
                    rule.location.line,
                    f"rule {rule.id!r} names {name}, which is not defined; expected a loaded message",
                )
    for name in loaded:
        rules_for(schema.rules, name)  # unique ids per message


def load_rules_dir(root: Path) -> tuple[CrossFieldRule, ...]:
    """Every ``*.yaml`` / ``*.yml`` file below ``root``, in sorted path order."""
    paths = sorted(p for p in root.rglob("*") if p.suffix in (".yaml", ".yml") and p.is_file())
    return tuple(rule for p in paths for rule in load_rule_file(p, root=root))


def rules_for(rules: tuple[CrossFieldRule, ...], qualified_name: str) -> tuple[CrossFieldRule, ...]:
    found: list[CrossFieldRule] = []
    seen: dict[str, Location] = {}
    for r in rules:
        if qualified_name in r.messages:
            if r.id in seen:
                raise SchemaError(
                    r.location.file,
                    r.location.line,
                    f"rule id {r.id!r} of {qualified_name} is used twice "
                    f"(first at {seen[r.id]}); expected unique ids per message",
                )
            seen[r.id] = r.location
            found.append(r)
    return tuple(found)


# --------------------------------------------------------------------------------------------
# Loading


@cache
def _schema() -> dict[str, Any]:
    text = resources.files(__package__).joinpath("rules.schema.json").read_text(encoding="utf-8")
    data: dict[str, Any] = json.loads(text)
    return data


def load_rule_file(path: Path, *, root: Path | None = None) -> tuple[CrossFieldRule, ...]:
    display = display_path(path, root)
    data = load_yaml(read_text(path, display), display, expected="YAML")
    if data is None:
        raise SchemaError(display, 1, "expected a rule file (a mapping with 'messages' and 'rules'), found nothing")
    errors = sorted(jsonschema.Draft202012Validator(_schema()).iter_errors(data), key=lambda e: list(e.path))
    if errors:
        err = jsonschema.exceptions.best_match(errors)
        at = "/".join(str(p) for p in err.absolute_path) or "the file"
        raise SchemaError(
            display, line_at(data, list(err.absolute_path)), f"{at}: {err.message} (see codegen/rules.schema.json)"
        )
    assert isinstance(data, YMap)
    messages = tuple(data["messages"])
    rules = tuple(_ir_rule(item, messages, display) for item in data["rules"])
    for rule in rules:
        parsed(rule)  # every expression parses, or the error names its line now
    return rules


def _ir_rule(item: YMap, messages: tuple[str, ...], file: str) -> CrossFieldRule:
    raw_for = item.get("for", [])
    loops = (raw_for,) if isinstance(raw_for, str) else tuple(raw_for)
    keyed = [(str(k), item.line_of(k)) for k in item]
    if isinstance(raw_for, YList):
        keyed += [(f"for[{j}]", line) for j, line in enumerate(raw_for.item_lines)]
    return CrossFieldRule(
        id=item["id"],
        messages=messages,
        severity=item.get("severity", "error"),
        check=item["assert"],
        location=Location(file, item.line),
        doc=item.get("doc", ""),
        where=item.get("where"),
        loops=loops,
        path=item.get("path"),
        message=item["message"],
        lines=tuple(keyed),
    )


@cache
def parsed(rule: CrossFieldRule) -> Rule:
    """The rule's expressions parsed (names still unresolved); errors name the key's line."""
    lines = dict(rule.lines)
    file = rule.location.file

    def fail(key: str, what: str, text: str, exc: ExprError) -> SchemaError:
        line = lines.get(key, lines.get(key.split("[")[0], rule.location.line))
        return SchemaError(file, line, f"{what} {text!r}: {exc.message} at column {exc.column}")

    def expr(text: str, key: str) -> Expr:
        try:
            return parse(text)
        except ExprError as exc:
            raise fail(key, f"in '{key}'", text, exc) from None

    bindings: list[tuple[str, Expr]] = []
    for j, text in enumerate(rule.loops):
        try:
            bindings.append(parse_binding(text))
        except ExprError as exc:
            raise fail(f"for[{j}]", "in 'for'", text, exc) from None
    try:
        message = parse_template(rule.message)
    except ExprError as exc:
        raise SchemaError(
            file, lines.get("message", rule.location.line), f"in 'message': {exc.message} at column {exc.column}"
        ) from None
    return Rule(
        id=rule.id,
        severity=rule.severity,
        doc=rule.doc,
        where=expr(rule.where, "where") if rule.where is not None else None,
        bindings=tuple(bindings),
        check=expr(rule.check, "assert"),
        path=expr(rule.path, "path") if rule.path is not None else None,
        message=message,
        text=rule.check,
        location=rule.location,
        lines=rule.lines,
    )


# --------------------------------------------------------------------------------------------
# Binding names to a message


@dataclass(frozen=True)
class BoundRule:
    rule: Rule
    where: Expr | None
    bindings: tuple[tuple[str, Expr], ...]
    check: Expr
    path: Expr | None
    message: tuple[str | Expr, ...]


def bind(rule: Rule, msg: Message) -> BoundRule:
    """Resolve the rule's names against ``msg``: fields, loop variables, constants."""
    fields = {f.name: f for f in msg.fields if not f.is_padding}
    constants = {c.name: c.value for c in msg.constants if not isinstance(c.value, str)}

    def resolve(expr: Expr, scope: frozenset[str], key: str) -> Expr:
        def r(e: Expr) -> Expr:
            return resolve(e, scope, key)

        if isinstance(expr, Name):
            if not expr.quoted and expr.text in scope:
                return VarRef(expr.text)
            if expr.text in fields:
                return FieldRef(fields[expr.text])
            if not expr.quoted and expr.text in constants:
                value = constants[expr.text]
                assert not isinstance(value, str)
                return Const(value)
            raise SchemaError(
                rule.location.file,
                rule.line_of(key),
                f"rule {rule.id!r}: {expr.text!r} (column {expr.column} of '{key}') is not a field, constant or "
                f"loop variable of {msg.qualified_name}",
            )
        if isinstance(expr, Unary):
            return Unary(expr.op, r(expr.operand))
        if isinstance(expr, Binary):
            return Binary(expr.op, r(expr.left), r(expr.right))
        if isinstance(expr, Compare):
            return Compare(expr.ops, tuple(r(e) for e in expr.operands))
        if isinstance(expr, BoolOp):
            return BoolOp(expr.op, tuple(r(e) for e in expr.values))
        if isinstance(expr, Not):
            return Not(r(expr.operand))
        if isinstance(expr, Index):
            return Index(r(expr.target), r(expr.index))
        if isinstance(expr, ListLit):
            return ListLit(tuple(r(e) for e in expr.items))
        if isinstance(expr, Quant):
            return Quant(expr.func, resolve(expr.body, scope | {expr.var}, key), expr.var, r(expr.iterable))
        if isinstance(expr, Call):
            args = tuple(r(a) for a in expr.args)
            if expr.func == "is_known" and not isinstance(args[0], FieldRef):
                raise SchemaError(
                    rule.location.file,
                    rule.line_of(key),
                    f"rule {rule.id!r}: is_known() takes a field name (column {expr.column} of '{key}')",
                )
            return Call(expr.func, args, expr.column)
        return expr

    scope: frozenset[str] = frozenset()
    where = resolve(rule.where, scope, "where") if rule.where is not None else None
    bindings: list[tuple[str, Expr]] = []
    for var, iterable in rule.bindings:
        if var in scope or var in fields:
            raise SchemaError(
                rule.location.file,
                rule.line_of("for"),
                f"rule {rule.id!r}: loop variable {var!r} hides a field or another loop variable; pick another name",
            )
        bindings.append((var, resolve(iterable, scope, "for")))
        scope = scope | {var}
    check = resolve(rule.check, scope, "assert")
    path = resolve(rule.path, scope, "path") if rule.path is not None else None
    if path is not None and not _is_place(path):
        raise SchemaError(
            rule.location.file,
            rule.line_of("path"),
            f"rule {rule.id!r}: expected 'path' to name a field or loop variable, optionally indexed",
        )
    message = tuple(p if isinstance(p, str) else resolve(p, scope, "message") for p in rule.message)
    return BoundRule(rule, where, tuple(bindings), check, path, message)


def _is_place(expr: Expr) -> bool:
    while isinstance(expr, Index):
        expr = expr.target
    return isinstance(expr, FieldRef | VarRef)


def referenced_fields(expr: Expr | None, *, skip_is_known: bool = True) -> list[str]:
    """Schema names of the fields ``expr`` reads, in first-use order (is_known() arguments aside)."""
    out: dict[str, None] = {}

    def walk(e: Expr | None) -> None:
        if e is None:
            return
        if isinstance(e, FieldRef):
            out[e.field.name] = None
        elif isinstance(e, Unary | Not):
            walk(e.operand)
        elif isinstance(e, Binary):
            walk(e.left)
            walk(e.right)
        elif isinstance(e, Compare):
            for x in e.operands:
                walk(x)
        elif isinstance(e, BoolOp):
            for x in e.values:
                walk(x)
        elif isinstance(e, Index):
            walk(e.target)
            walk(e.index)
        elif isinstance(e, ListLit):
            for x in e.items:
                walk(x)
        elif isinstance(e, Quant):
            walk(e.body)
            walk(e.iterable)
        elif isinstance(e, Call) and not (skip_is_known and e.func == "is_known"):
            for x in e.args:
                walk(x)

    walk(expr)
    return list(out)

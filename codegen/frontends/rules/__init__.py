"""Cross-field rules: declarative YAML files in ``schemas/rules/``, read into the IR
(:class:`~codegen.ir.CrossFieldRule`, in ``Schema.rules``) and compiled by the validators into
each generated ``validate()``.

A rule file names the messages it applies to and lists rules; each rule has an ``assert``
expression (the language is parsed by :mod:`.parse` into the AST of :mod:`codegen.ir.expr`),
optional ``where`` precondition and ``for`` loops, a ``message`` template with ``{expr}``
placeholders and a severity (``warning`` for advice). :func:`load_rules_dir` checks each file
against ``rules.schema.json`` and parses every expression (:mod:`.files`); once the messages are
loaded, :func:`check_rules` checks that every rule binds to each message it names (:mod:`.binding`).
Any problem is a :class:`~codegen.errors.SchemaError` naming the file and line.

Semantics the compiled code keeps: a rule is skipped while a devicetree property it reads is
absent; a rule whose evaluation fails (an index out of range, a value of the wrong type) is skipped
too, since the field checks already report the cause.
"""

from __future__ import annotations

from pathlib import Path

from ...errors import SchemaError
from ...ir import CrossFieldRule, Location, Schema
from .binding import check_binding
from .files import load_rule_file


def load_rules_dir(root: Path) -> tuple[CrossFieldRule, ...]:
    """Every ``*.yaml`` / ``*.yml`` file below ``root``, in sorted path order."""
    paths = sorted(p for p in root.rglob("*") if p.suffix in (".yaml", ".yml") and p.is_file())
    return tuple(rule for p in paths for rule in load_rule_file(p, root=root))


def check_rules(schema: Schema) -> None:
    """Every rule names loaded messages and binds to each; a message of a format that is not
    loaded at all is allowed (a rules folder may serve a subset of the schemas)."""
    loaded = {m.qualified_name: m for m in schema.messages}
    formats = {name.split(".", 1)[0] for name in loaded}
    for rule in schema.rules:
        for name in rule.messages:
            if name in loaded:
                check_binding(rule, loaded[name])
            elif name.split(".", 1)[0] in formats:
                raise SchemaError(
                    rule.location.file,
                    rule.location.line,
                    f"rule {rule.id!r} names {name}, which is not defined; expected a loaded message",
                )
    for name in loaded:
        check_unique_ids(schema.rules, name)


def check_unique_ids(rules: tuple[CrossFieldRule, ...], qualified_name: str) -> None:
    """The rules for one message have distinct ids (a violation names its rule by id)."""
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


__all__ = [
    "check_binding",
    "check_rules",
    "check_unique_ids",
    "load_rule_file",
    "load_rules_dir",
]

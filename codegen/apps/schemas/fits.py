"""The one meaning of "a record's values fit" (issue 32): what ``battgen validate`` counts as an error of a
record, for validate itself, for ``convert --policy strict`` (which refuses exactly such a record) and for the
failsafe (which never takes a value validate refuses as a reading).

The verdict comes from one place, the generated ``validate()``: written from the IR's types, ranges, enums,
bitmasks, "unknown" sentinels and cross-field rules. This module reads it as validate reads it:

- a violation of a field the source lacks (an older ULog layout: the field holds the schema's default) is not
  the record's, nor is one of a cross-field rule that reads such a field (:func:`left_out`, :func:`rule_fields`);
- a finding a gate waives is not an error: validate's gate applies the profile of a log's firmware
  (``gate/profiles/px4.yaml``: PX4 writes ``max_error = 0``, a field it never sets) unless told otherwise;
- warnings are not errors.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import Protocol

from ...inputs.model import Violation
from ...ir import Message, Schema
from ...ir.expr import referenced_fields
from ...ir.rules import bound_rules

CROSS = "cross-field:"
RuleFields = Mapping[str, frozenset[str]]  # a cross-field rule's id -> the fields it reads


class Waivers(Protocol):
    """What leaves a finding out (validate's ``Gate``): None when it is reported, else why not."""

    def why_not(self, rule: str, path: str) -> str | None: ...


def rule_fields(schema: Schema, message: Message) -> dict[str, frozenset[str]]:
    """Cross-field rule id -> the fields it reads (is_known() arguments included)."""
    out: dict[str, frozenset[str]] = {}
    for bound in bound_rules(schema, message):
        exprs = [bound.where, bound.check, bound.path, *(e for _, e in bound.bindings)]
        exprs += [p for p in bound.message if not isinstance(p, str)]
        names = {n for e in exprs for n in referenced_fields(e, skip_is_known=False)}
        out[bound.rule.id] = frozenset(names)
    return out


def covers(skip: frozenset[str], path: str) -> bool:
    """True when ``path`` (``a``, ``a[3]``, ``a.b``) lies in a skipped field."""
    return any(path == s or path.startswith((s + ".", s + "[")) for s in skip)


def left_out(violation: Violation, skip: frozenset[str], rules: RuleFields) -> bool:
    """A violation that is not the record's: of a field the source lacks, or of a cross-field rule reading one."""
    rule = str(violation.rule)
    if rule.startswith(CROSS) and rules.get(rule[len(CROSS) :], frozenset()) & skip:
        return True
    return covers(skip, str(violation.path))


def errors(
    violations: Iterable[Violation],
    *,
    skip: frozenset[str] = frozenset(),
    rules: RuleFields | Callable[[], RuleFields] | None = None,
    gate: Waivers | None = None,
) -> list[Violation]:
    """The violations validate reports as errors of a record: not warnings, not left out (``rules``, or what
    gives them: asked for only when a cross-field rule broke in a record lacking a field), not waived by
    ``gate``."""
    out = []
    for v in violations:
        if v.severity == "warning":
            continue
        if skip:
            if callable(rules) and str(v.rule).startswith(CROSS):  # only a cross-field rule asks what it reads
                rules = rules()
            if left_out(v, skip, {} if callable(rules) or rules is None else rules):
                continue
        if gate is not None and gate.why_not(str(v.rule), str(v.path)) is not None:
            continue
        out.append(v)
    return out

"""Every problem of a devicetree node, in the order and granularity of dt-schema's dt-validate.

dt-validate checks a node against the binding its compatible selects, then against the schemas
that apply to every node; within the binding, the processed schema's keywords come in sorted
order. So a node's report is:

1. ``additionalProperties``: one problem naming every property the binding does not define;
2. ``patternProperties``: per pattern (sorted), the matching properties in node order;
3. ``properties``: per property, by name;
4. ``required``: the missing ones;
5. dt-core: every property whose value stayed raw bytes -- a value that does not decode as its
   type, or a property no schema gives a type (dt-validate decodes a blob by the types it knows:
   unit suffixes, core properties, the bindings' own);
6. property-units: a property typed by its unit suffix whose value stayed raw bytes.

A node is never reported only up to its first problem: a property that does not read is
reported and left out, and the rest of the node is built and validated.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from ...frontends.devicetree.refs import CORE_TYPES
from ...inputs.devicetree.mapping import field_for
from ...inputs.model import GeneratedMessage, MessageClass
from ...ir import ArrayType, Message
from ...ir.units import devicetree_suffix_unit
from ...text.brief import clip

UNKNOWN_RULE = "additional-properties"
RAW_RULE = "dt-core-type"
UNIT_RULE = "unit-type"
LENGTH_RULE = "length"
NAMES_SHOWN = 8  # a message names this many unknown properties and counts the rest


def quoted(name: str) -> str:
    """A property name as a message shows it: the data's keys are unbounded, a message is not."""
    return clip(name)


def name_list(names: list[str]) -> str:
    """Names for a message: the first NAMES_SHOWN, each clipped, and how many more there are."""
    shown = ", ".join(quoted(n) for n in names[:NAMES_SHOWN])
    more = len(names) - NAMES_SHOWN
    return shown + (f" and {more} more" if more > 0 else "")


@dataclass(frozen=True)
class Problem:
    """A problem found before ``validate()`` can run: (path, rule, value, limit, text)."""

    path: str
    rule: str
    value: object
    limit: object
    text: str


def top_property(path: str, names: Mapping[str, object]) -> str:
    """The node property a finding path (``ocv-capacity-table-0[1][0]``) lies in."""
    best = ""
    for name in names:
        if (path == name or path.startswith((name + "[", name + "."))) and len(name) > len(best):
            best = name
    return best or re.split(r"[\[]", path, maxsplit=1)[0]


def _typed_by_name(name: str) -> bool:
    return name in CORE_TYPES or devicetree_suffix_unit(name) is not None


def read_node(
    cls: MessageClass,
    message: Message,
    data: Mapping[str, Any],
    data_error: type[BaseException],
    type_problem: Callable[[BaseException], Problem],
) -> tuple[GeneratedMessage | None, list[Problem]]:
    """The instance built from every property that reads, and the problems of those that do not.

    ``type_problem`` turns a generated ``DataError`` into a Problem (the caller's wording)."""
    info = message.devicetree
    unknown = [name for name in data if field_for(message, name) is None]
    problems: list[Problem] = []
    if unknown and (info is None or not info.additional_properties):
        names = sorted(unknown)
        verb = "is" if len(names) == 1 else "are"
        text = f"{name_list(names)} {verb} not defined by {message.qualified_name} (additionalProperties: false)"
        problems.append(Problem(names[0], UNKNOWN_RULE, names, "a property of the binding", text))
    for name in unknown:
        if data[name] is not True and not _typed_by_name(name):  # dt-validate keeps its raw bytes
            text = f"{quoted(name)}: no schema gives this property a type, so its value stays raw bytes"
            problems.append(Problem(name, RAW_RULE, data[name], "a typed value", text))
    remaining = {k: v for k, v in data.items() if k not in unknown}
    for name, value in data.items():
        if name in remaining and isinstance(value, bytes):  # the cells do not decode as the type
            raw_text = f"{quoted(name)}: value does not decode as its type"
            problems.append(Problem(name, RAW_RULE, value, "a typed value", raw_text))
            if devicetree_suffix_unit(name) is not None:
                unit_text = f"{quoted(name)}: value is not an array of cells, as its unit suffix requires"
                problems.append(Problem(name, UNIT_RULE, value, "an array", unit_text))
            del remaining[name]
    stand_ins: set[str] = set()
    rounds = len(remaining) + sum(len(v) for v in remaining.values() if isinstance(v, list)) + 1
    for _ in range(rounds):  # each round drops a property or stands in for one of its items
        try:
            instance: GeneratedMessage = cls.from_dict(remaining)
        except data_error as exc:
            problem = type_problem(exc)
            problems.append(problem)
            name = top_property(problem.path, remaining)
            if name not in remaining:
                return None, problems
            if not _stand_in(remaining, name, problem.path, stand_ins):
                del remaining[name]
            continue
        problems += _const_lengths(message, remaining)
        return instance, problems
    return None, problems


def _stand_in(data: dict[str, Any], name: str, path: str, done: set[str]) -> bool:
    """dt-validate checks every item of a list on its own: an item that does not read is replaced by
    another item of the same list (its findings are then dropped, see ``stood_in``), so the other
    items are still checked. False when there is no item to stand in."""
    m = re.match(re.escape(name) + r"\[(\d+)\]", path)
    value = data[name]
    if m is None or not isinstance(value, list):
        return False
    bad = int(m.group(1))
    item_path = f"{name}[{bad}]"
    spare = [i for i in range(len(value)) if i != bad and f"{name}[{i}]" not in done]
    if item_path in done or not spare or bad >= len(value):
        return False
    done.add(item_path)
    data[name] = [*value[:bad], value[spare[0]], *value[bad + 1 :]]
    return True


def stood_in(path: str, problems: list[Problem]) -> bool:
    """Whether a ``validate()`` finding lies in an item ``read_node`` replaced (already reported)."""
    return any(p.rule == "type" and (path == p.path or path.startswith((p.path + "[", p.path + "."))) for p in problems)


def left_out_fields(message: Message, data: Mapping[str, Any], problems: list[Problem]) -> frozenset[str]:
    """The schema fields (pattern fields by their pattern) of the properties ``read_node`` left out."""
    out = set()
    for p in problems:
        if p.rule in (UNKNOWN_RULE, LENGTH_RULE):  # unknown: not in the model; too long: still read
            continue
        f = field_for(message, top_property(p.path, data))
        if f is not None:
            out.add(f.name)
    return frozenset(out)


def _const_lengths(message: Message, data: Mapping[str, Any]) -> list[Problem]:
    """dt-schema makes ``const: x`` on a string-array property a one-item array (``maxItems: 1``)."""
    out = []
    for name, value in data.items():
        f = field_for(message, name)
        if f is not None and f.const is not None and isinstance(f.type, ArrayType) and isinstance(value, list):
            if len(value) > 1:
                text = f"{quoted(name)} has {len(value)} items, more than 1"
                out.append(Problem(name, LENGTH_RULE, len(value), 1, text))
    return out


def order_key(message: Message, data: Mapping[str, Any], path: str, rule: str) -> tuple[Any, ...]:
    """Where a finding comes in dt-validate's report of the node (see the module docstring)."""
    if rule == UNKNOWN_RULE:
        return (0,)
    name = top_property(path, data)
    position = list(data).index(name) if name in data else 0
    if rule == RAW_RULE:
        return (5, position)
    if rule == UNIT_RULE:
        return (6, position)
    if rule.startswith("cross-field:"):
        return (7,)
    f = field_for(message, name)
    if name not in data:
        return (4, name)  # required
    if f is None:
        return (7,)
    items = tuple(int(i) for i in re.findall(r"\[(\d+)\]", path[len(name) :]))  # in item order, as dt-validate
    if f.pattern is not None:
        patterns = sorted(g.pattern for g in message.fields if g.pattern is not None)
        return (1, patterns.index(f.pattern), position, items)
    return (2, name, 1 if rule == LENGTH_RULE else 0, items)  # items[0] comes before maxItems

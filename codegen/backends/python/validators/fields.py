"""The statements of ``validate()`` checking one field: the fast-path test, and the careful
diagnosis by the runtime when it trips (or when the value is of a type the test cannot take)."""

from __future__ import annotations

from dataclasses import dataclass

from ....ir import Field, Message, Schema
from ..literals import py_literal, unparenthesized
from .checks import ArrayCheck, NestedCheck, NumberCheck, V, build


@dataclass(frozen=True)
class FieldCode:
    spec_name: str
    spec_source: str
    lines: list[str]  # statements in validate(), unindented (inside the one try of the field checks)
    names: frozenset[str]  # locals the statements assign (validate() declares them)


def field_code(schema: Schema, msg: Message, f: Field, ident: str, spec_name: str) -> FieldCode:
    """Statements checking ``self.<ident>`` and appending violations to ``out``."""
    check = build(schema, f, f.type)
    optional = is_optional(msg, f)
    spec = check.spec()
    if f.pattern is not None:
        spec = f"_v.Pattern({py_literal(f.pattern)}, {spec})"
    elif optional:
        spec = f"_v.Optional({spec}, required={py_literal(f.required)})"
    path = py_literal(f.name)
    attr = f"self.{ident}"
    slow = f"_v.diag(out, {path}, {attr}, {spec_name})"
    names: set[str] = set()
    if isinstance(check, NestedCheck):
        names |= {"x", "sub"}
        absent = []
        if optional:  # an absent branch of a union (or optional property) is checked by the union's own test
            absent = ["if x is None:", f"    {slow}" if f.required else "    pass"]
        body = [
            f"x = {attr}",
            *absent,
            f"{'elif' if absent else 'if'} x.QUALIFIED_NAME != {py_literal(check.qualified)}:",
            f"    {slow}",
            "else:",
            "    sub = x.validate()",
            "    if sub:",
            f"        out.extend(_v.prefixed({path}, sub))",
        ]
    elif f.pattern is not None:
        cond = check.bad().replace(V, "x")
        body = [
            f"if any(not _v.search({py_literal(f.pattern)}, k) or {cond} for k, x in {attr}.items()):",
            f"    {slow}",
        ]
    elif isinstance(check, ArrayCheck) and not check.byte and not check.ranged and isinstance(check.inner, NumberCheck):
        # top-level array of numbers: a plain loop beats any() with a generator
        length = check.length_bad()
        item = check.inner.bad().replace(V, "e")
        names |= {"a", "e"}
        if optional and f.required:
            head, ind = [f"a = {attr}", "if a is None:", f"    {slow}", "else:"], "    "
        elif optional:
            head, ind = [f"a = {attr}", "if a is not None:"], "    "
        else:
            head, ind = [f"a = {attr}"], ""
        loop = ["for e in a:", f"    if {unparenthesized(item)}:", f"        {slow}", "        break"]
        if length:
            cond = " or ".join(length).replace(V, "a")
            inner = [f"if {cond}:", f"    {slow}", "else:", *["    " + x for x in loop]]
        else:
            inner = loop
        body = head + [ind + x for x in inner]
    else:
        cond = check.bad()
        if optional:
            names.add("x")
            if f.required:
                cond = f"(x := {attr}) is None or {cond.replace(V, 'x')}"
            else:
                cond = f"(x := {attr}) is not None and {cond.replace(V, 'x')}"
            body = [f"if {cond}:", f"    {slow}"]
        elif cond.count(V) == 1:
            body = [f"if {unparenthesized(cond).replace(V, attr)}:", f"    {slow}"]
        else:  # the value is tested more than once: read the attribute once
            names.add("x")
            body = [f"x = {attr}", f"if {unparenthesized(cond).replace(V, 'x')}:", f"    {slow}"]
    return FieldCode(spec_name, spec, body, frozenset(names))


def is_optional(msg: Message, f: Field) -> bool:
    """Whether the field's value may be None: a devicetree property, or a branch of a DSDL union."""
    if f.pattern is not None:
        return False
    return msg.devicetree is not None or msg.is_union

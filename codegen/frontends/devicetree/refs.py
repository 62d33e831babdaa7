"""Which types.yaml type a dt-schema property has.

The order follows dt-schema's own reading of a binding: an explicit ``$ref`` to types.yaml, a
nested node, ``type: boolean``, the types of allOf/oneOf/anyOf alternatives, the unit-suffix
rules of property-units.yaml, a few core properties every binding may use, and finally string
constraints (const/enum/pattern), which imply a string.  Anything else stays unknown.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any
from urllib.parse import urljoin

from ...errors import SchemaError
from ...text.yaml_lines import YList, YMap
from .data import DtData

# Core properties (devicetree specification / dt-schema's core schemas), for bindings that
# list them without a type.
CORE_TYPES: dict[str, str] = {
    "compatible": "string-array",
    "model": "string",
    "status": "string",
    "label": "string",
    "device_type": "string",
    "phandle": "uint32",
    "#address-cells": "uint32",
    "#size-cells": "uint32",
    "#interrupt-cells": "uint32",
    "#clock-cells": "uint32",
    "#gpio-cells": "uint32",
    "#reset-cells": "uint32",
    "#power-domain-cells": "uint32",
    "#dma-cells": "uint32",
    "#phy-cells": "uint32",
    "#pwm-cells": "uint32",
    "reg": "address",
    "reg-names": "string-array",
    "interrupts": "uint32-matrix",
    "interrupt-names": "string-array",
    "interrupt-parent": "phandle",
    "interrupts-extended": "phandle-array",
    "interrupt-controller": "flag",
    "clocks": "phandle-array",
    "clock-names": "string-array",
    "resets": "phandle-array",
    "reset-names": "string-array",
    "power-domains": "phandle-array",
    "power-domain-names": "string-array",
    "dmas": "phandle-array",
    "dma-names": "string-array",
    "pinctrl-names": "string-array",
    "dma-coherent": "flag",
    "gpio-controller": "flag",
    "wakeup-source": "flag",
    "monitored-battery": "phandle",
    "power-supplies": "phandle-array",
    "ranges": "uint32-matrix",  # or empty (a flag) for a 1:1 mapping
    "dma-ranges": "uint32-matrix",
    "clock-frequency": "uint32",
    "clock-output-names": "string-array",
    "numa-node-id": "uint32",
    "interrupt-map": "uint32-matrix",
    "interrupt-map-mask": "uint32-array",
    "operating-points-v2": "phandle",
}
# Core name patterns: regulator supplies, GPIO lists, "#...-cells" counts, pinctrl states.
CORE_PATTERNS: tuple[tuple[re.Pattern[str], str], ...] = (
    (re.compile(r"^#[a-z0-9-]+-cells$"), "uint32"),
    (re.compile(r"^[a-z0-9-]+-supply$"), "phandle"),
    (re.compile(r"^([a-z0-9-]+-)?gpios?$"), "phandle-array"),
    (re.compile(r"^pinctrl-[0-9]+$"), "phandle-array"),
)

# $ref to a types.yaml definition, absolute (/schemas/..., http://devicetree.org/schemas/...)
# or relative (types.yaml#..., ../types.yaml#...)
_TYPES_REF = re.compile(r"^(?:(?:https?://devicetree\.org)?/schemas/|(?:\.\./)*)types\.yaml#/definitions/(?P<name>.*)$")
# a URI reference without blanks whose fragment, if any, is empty or a JSON pointer
_REF_SYNTAX = re.compile(r"^[^\s#]*(?:#(?:/\S*)?)?$")
_NODE_KEYS = frozenset({"properties", "patternProperties", "additionalProperties"})
_MAX_DEPTH = 24  # local $ref chains deeper than this are treated as cycles


@dataclass(frozen=True)
class Resolved:
    """A property's type: a types.yaml definition, "node", or None when nothing says."""

    dt_type: str | None
    source: str  # ref, node, boolean, unit-suffix, core, strings, unknown
    target: str | None = None  # for a node: the $ref'd schema URI or local "#/..." pointer
    others: tuple[str, ...] = ()  # further types allowed by oneOf/anyOf alternatives


UNKNOWN = Resolved(None, "unknown")


@dataclass(frozen=True)
class RefContext:
    display: str
    doc: YMap
    base_uri: str
    data: DtData


def check_ref(ctx: RefContext, owner: YMap) -> str:
    ref = owner.get("$ref")
    if not isinstance(ref, str) or not ref or not _REF_SYNTAX.match(ref):
        raise SchemaError(
            ctx.display,
            owner.line_of("$ref"),
            f"expected $ref to be a URI reference such as /schemas/types.yaml#/definitions/uint32, not {ref!r}",
        )
    return ref


def pointer(doc: Any, fragment: str) -> Any:
    """Follow a JSON pointer ("/a/b") into a loaded document; None when it leads nowhere."""
    node = doc
    for raw in fragment.split("/")[1:]:
        part = raw.replace("~1", "/").replace("~0", "~")
        if isinstance(node, YMap) and part in node:
            node = node[part]
        elif isinstance(node, YList) and part.isdigit() and int(part) < len(node):
            node = node[int(part)]
        else:
            return None
    return node


def is_string_schema(schema: Any) -> bool:
    """A schema whose const/enum/pattern holds strings, so the value is text."""
    if not isinstance(schema, YMap):
        return False
    for key in ("const", "enum", "pattern"):
        value = schema.get(key)
        first = value[0] if isinstance(value, list) and value else value
        if isinstance(first, str):
            return True
    return schema.get("type") == "string"


def resolve(ctx: RefContext, name: str, schema: Any, *, is_pattern: bool, depth: int = 0) -> Resolved:
    if depth > _MAX_DEPTH:
        return UNKNOWN
    if not isinstance(schema, YMap):
        return _fallback(ctx, name, schema, is_pattern)
    ref = check_ref(ctx, schema) if "$ref" in schema else None
    if schema.get("type") == "object" or _NODE_KEYS & schema.keys():
        return Resolved("node", "node")
    if ref is not None:
        found = _resolve_ref(ctx, name, schema, ref, is_pattern, depth)
        if found.dt_type is not None:
            return found
    if schema.get("type") == "boolean":
        return Resolved("flag", "boolean")
    found_types: list[Resolved] = []
    for key in ("allOf", "oneOf", "anyOf"):
        subs = schema.get(key)
        if isinstance(subs, list):
            for sub in subs:
                r = resolve(ctx, name, sub, is_pattern=is_pattern, depth=depth + 1)
                if r.dt_type is not None and all(r.dt_type != f.dt_type for f in found_types):
                    found_types.append(r)
    if found_types:
        first = found_types[0]
        return Resolved(first.dt_type, first.source, first.target, tuple(str(f.dt_type) for f in found_types[1:]))
    return _fallback(ctx, name, schema, is_pattern)


def _resolve_ref(ctx: RefContext, name: str, owner: YMap, ref: str, is_pattern: bool, depth: int) -> Resolved:
    types_ref = _TYPES_REF.match(ref)
    if types_ref is not None:
        definition = types_ref.group("name")
        if definition not in ctx.data.types:
            known = ", ".join(sorted(ctx.data.types))
            raise SchemaError(
                ctx.display, owner.line_of("$ref"), f"expected a types.yaml definition ({known}), not {definition!r}"
            )
        return Resolved(definition, "ref")
    where, _, fragment = ref.partition("#")
    prop = fragment.rsplit("/properties/", 1)[1] if "/properties/" in fragment else None
    if not where:  # a local pointer into this binding
        target = pointer(ctx.doc, fragment)
        if target is None:
            raise SchemaError(ctx.display, owner.line_of("$ref"), f"expected $ref {ref!r} to point into this file")
        found = resolve(ctx, prop or name, target, is_pattern=is_pattern and prop is None, depth=depth + 1)
        if found.dt_type == "node" and found.target is None:
            return Resolved("node", "ref", target=ref)
        return found
    if prop is not None:  # another schema's property: its type by name
        return _fallback(ctx, prop, True, False)
    return Resolved("node", "ref", target=urljoin(ctx.base_uri, ref))


def _fallback(ctx: RefContext, name: str, schema: Any, is_pattern: bool) -> Resolved:
    rule = ctx.data.unit_rule(name)
    if rule is not None:
        return Resolved(rule.type, "unit-suffix")
    if not is_pattern and name in CORE_TYPES:
        return Resolved(CORE_TYPES[name], "core")
    for regex, core_type in CORE_PATTERNS if not is_pattern else ():
        if regex.match(name):
            return Resolved(core_type, "core")
    if not isinstance(schema, YMap):
        return UNKNOWN
    if is_string_schema(schema):
        return Resolved("string", "strings")
    alternatives = [s for k in ("oneOf", "anyOf") if isinstance(schema.get(k), list) for s in schema[k]]
    if alternatives and all(is_string_schema(s) for s in alternatives):
        return Resolved("string", "strings")
    items = schema.get("items")
    first = items[0] if isinstance(items, list) and items else items
    if is_string_schema(first):
        return Resolved("string-array", "strings")
    return UNKNOWN

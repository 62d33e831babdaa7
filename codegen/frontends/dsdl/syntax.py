"""DSDL v0 (DroneCAN / UAVCAN v0) source syntax: type expressions, attribute lines, directives.

This module turns the text of one ``.uavcan`` file into a :class:`~.definitions.TypeDef` without
touching other files: composite references are resolved lexically to full names here and located
by :mod:`.namespaces` (file and namespace names are checked in :mod:`.names`).
The rules follow the DSDL v0 specification as the reference tools apply it, e.g. comments
run from ``#`` to the end of the line, whitespace inside a constant initialiser is ignored,
``[<N]`` means at most N-1 elements, ``uint1`` is spelled ``bool``.
"""

from __future__ import annotations

import re

from ...errors import SchemaError
from ...ir.fieldtypes import MAX_ARRAY_CAPACITY
from .definitions import ArrayT, AttrT, ConstDef, FieldDef, PrimT, RefT, Section, TypeDef, VoidT
from .expr import ExpressionError, evaluate
from .names import valid_namespace_component, valid_type_name

MAX_MESSAGE_ID = 65535
MAX_SERVICE_ID = 255

_ATTR_NAME_RE = re.compile(r"[a-zA-Z][a-zA-Z0-9_]*\Z")
_VOID_RE = re.compile(r"void(\d+)\Z")
_ARRAY_RE = re.compile(r"(.+?)\[([^\]]*)\]\Z")
_PRIMITIVE_RE = re.compile(r"(bool)\Z|([a-z]+)(\d+)\Z")

_CAST_MODES = ("saturated", "truncated")


# --------------------------------------------------------------------------------------------
# Type expressions


class _LineError(Exception):
    """A problem on the current line; turned into SchemaError with the file and line."""


def parse_type(text: str, cast: str | None, namespace: str) -> AttrT:
    void = _VOID_RE.match(text)
    if void:
        bits = int(void.group(1))
        if not 1 <= bits <= 64:
            raise _LineError(f"expected a void width between 1 and 64, got {text!r}")
        return VoidT(bits)
    array = _ARRAY_RE.match(text)
    if array:
        element = parse_type(array.group(1).strip(), cast, namespace)
        if isinstance(element, ArrayT):
            raise _LineError("expected a one-dimensional array (wrap the inner array in a composite type)")
        if isinstance(element, VoidT):
            raise _LineError("expected a non-void array element")
        size, dynamic = _array_bound(array.group(2).strip())
        return ArrayT(element, size, dynamic)
    primitive = _PRIMITIVE_RE.match(text)
    if primitive:
        return _primitive(primitive, text, cast)
    if cast is not None:
        raise _LineError(f"expected no cast mode before the composite type {text!r}")
    full_name = text if "." in text else f"{namespace}.{text}"
    short = full_name.rpartition(".")[2]
    components = full_name.split(".")[:-1]
    if not (valid_type_name(short) and all(valid_namespace_component(c) for c in components)):
        raise _LineError(
            f"unknown type {text!r}: expected bool, uintN, intN, floatN, voidN, an array of one, "
            "or a composite type name (CamelCase, optionally namespace-qualified)"
        )
    return RefT(full_name)


def _array_bound(spec: str) -> tuple[int, bool]:
    try:
        if spec.startswith("<="):
            size, dynamic = int(spec[2:], 0), True
        elif spec.startswith("<"):
            size, dynamic = int(spec[1:], 0) - 1, True
        else:
            size, dynamic = int(spec, 0), False
    except ValueError:
        raise _LineError(f"expected an array bound [N], [<N] or [<=N] with an integer N, got [{spec}]") from None
    if size <= 0:
        raise _LineError(f"expected an array capacity of at least 1, got [{spec}]")
    if size > MAX_ARRAY_CAPACITY:
        raise _LineError(f"expected an array capacity of at most {MAX_ARRAY_CAPACITY} (docs/limits.md), got [{spec}]")
    return size, dynamic


def _primitive(match: re.Match[str], text: str, cast: str | None) -> PrimT:
    mode = cast or "saturated"
    if match.group(1):
        return PrimT("bool", 1, mode)
    base, bits = match.group(2), int(match.group(3))
    if base == "float":
        if bits not in (16, 32, 64):
            raise _LineError(f"expected float16, float32 or float64, got {text!r}")
    elif base in ("uint", "int"):
        if not 2 <= bits <= 64:
            raise _LineError(f"expected a {base} width between 2 and 64 (use bool for one bit), got {text!r}")
    else:
        raise _LineError(
            f"unknown primitive type {text!r}: expected bool, uintN, intN or floatN (composite types are CamelCase)"
        )
    return PrimT(base, bits, mode)


def _constant_value(ptype: PrimT, expression: str) -> int | float | bool:
    try:
        raw = evaluate(expression)
    except ExpressionError as exc:
        raise _LineError(str(exc)) from None
    value: int | float | bool
    try:
        number = ord(raw) if isinstance(raw, str) else raw
        value = float(number) if ptype.kind == "float" else int(number)
    except (OverflowError, ValueError):
        raise _LineError(f"expected a finite value for {ptype.normalized}, got {expression!r}") from None
    low, high = ptype.value_range
    if not low <= value <= high:
        raise _LineError(f"expected a value within [{low}, {high}] for {ptype.normalized}, got {value!r}")
    return bool(value) if ptype.kind == "bool" else value


# --------------------------------------------------------------------------------------------
# Lines


def _comment_text(comment: str) -> str:
    """One comment line's text: '# ' dropped, the rest (indentation included) kept."""
    return (comment[1:] if comment.startswith(" ") else comment).rstrip()


def _block(lines: list[str]) -> str:
    while lines and not lines[0].strip():
        lines = lines[1:]
    while lines and not lines[-1].strip():
        lines = lines[:-1]
    return "\n".join(lines)


class _SectionBuilder:
    def __init__(self, line: int) -> None:
        self.line = line
        self.fields: list[FieldDef] = []
        self.constants: list[ConstDef] = []
        self.union = False
        self.names: dict[str, int] = {}

    def claim(self, name: str, line: int) -> None:
        if name in self.names:
            raise _LineError(f"expected a unique name; {name!r} is already defined on line {self.names[name]}")
        self.names[name] = line

    def build(self, file: str) -> Section:
        if self.union:
            if len(self.fields) < 2:
                raise SchemaError(file, self.line, "expected at least 2 fields in a @union")
            for f in self.fields:
                if isinstance(f.type, VoidT):
                    raise SchemaError(file, f.line, "expected no void fields in a @union")
        return Section(tuple(self.fields), tuple(self.constants), self.union, self.line)


def parse_source(
    text: str, *, file: str, full_name: str, default_id: int | None, version: tuple[int, int] | None
) -> TypeDef:
    """Parse one definition; ``full_name`` and ``default_id`` come from the file's path and name."""
    namespace = full_name.rpartition(".")[0]
    sections = [_SectionBuilder(1)]
    override: int | None = None
    doc: str | None = None  # the top-of-file comment block, once closed
    pending: list[str] = []  # comment lines directly above the current line
    for lineno, raw in enumerate(text.splitlines(), 1):
        code, hash_, comment = raw.partition("#")
        tokens = code.split()
        if not tokens:
            if hash_:
                pending.append(_comment_text(comment))
            else:  # a blank line ends a comment block
                if doc is None and pending:
                    doc = _block(pending)
                pending = []
            continue
        if doc is None:
            doc, pending = _block(pending), []
        above, pending = _block(pending), []
        trailing = comment.strip() if hash_ else ""
        try:
            override = _directive_or_attribute(tokens, sections, namespace, lineno, above, trailing, override)
        except _LineError as exc:
            raise SchemaError(file, lineno, str(exc)) from None
    request = sections[0].build(file)
    response = sections[1].build(file) if len(sections) > 1 else None
    if default_id is not None:
        limit = MAX_SERVICE_ID if response is not None else MAX_MESSAGE_ID
        if default_id > limit:
            what = "service" if response is not None else "message"
            raise SchemaError(file, 0, f"expected a {what} data type id within 0..{limit}, got {default_id}")
    return TypeDef(full_name, file, default_id, version, request, response, override, doc or "")


def _directive_or_attribute(
    tokens: list[str],
    sections: list[_SectionBuilder],
    namespace: str,
    line: int,
    above: str,
    trailing: str,
    override: int | None,
) -> int | None:
    """Apply one non-empty line; returns the (possibly updated) signature override."""
    section = sections[-1]
    if tokens == ["---"]:
        if len(sections) > 1:
            raise _LineError("expected at most one '---' service separator")
        sections.append(_SectionBuilder(line))
        return override
    if tokens[0].startswith("@"):
        if tokens != ["@union"]:
            raise _LineError(f"expected '@union' (the only DSDL v0 directive), got {' '.join(tokens)!r}")
        if section.union:
            raise _LineError("expected a single @union per data structure")
        section.union = True
        return override
    if tokens[0] == "OVERRIDE_SIGNATURE":
        if len(tokens) != 2:
            raise _LineError("expected 'OVERRIDE_SIGNATURE <hexadecimal 64-bit value>'")
        try:
            value = int(tokens[1], 16)
        except ValueError:
            raise _LineError(f"expected a hexadecimal signature, got {tokens[1]!r}") from None
        if not 0 <= value < 1 << 64:
            raise _LineError("expected a 64-bit signature")
        return value
    _attribute(tokens, section, namespace, line, above, trailing)
    return override


def _attribute(
    tokens: list[str], section: _SectionBuilder, namespace: str, line: int, above: str, trailing: str
) -> None:
    cast: str | None = None
    if tokens[0] in _CAST_MODES:
        cast, tokens = tokens[0], tokens[1:]
    if not tokens:
        raise _LineError("expected a type after the cast mode")
    if len(tokens) == 1 and not tokens[0].startswith("void"):
        raise _LineError(f"expected '<type> <name>' or '<type> <NAME> = <value>', got {tokens[0]!r} alone")
    name = tokens[1] if len(tokens) > 1 else None
    if name is not None and not _ATTR_NAME_RE.match(name):
        raise _LineError(f"expected a name of letters, digits and '_' starting with a letter, got {name!r}")
    atype = parse_type(tokens[0], cast, namespace)
    rest = tokens[2:]
    if name is not None:
        section.claim(name, line)
    if not rest:
        section.fields.append(FieldDef(name, atype, line, above, trailing))
        return
    if rest[0] != "=" or len(rest) < 2:
        raise _LineError(f"expected '= <value>' after {name!r}, got {' '.join(rest)!r}")
    if not isinstance(atype, PrimT) or name is None:
        raise _LineError("expected a primitive type (bool, uintN, intN, floatN) for a constant")
    # The reference tools drop all whitespace inside an initialiser before evaluating it.
    value = _constant_value(atype, "".join(rest[1:]))
    section.constants.append(ConstDef(name, atype, value, line, above, trailing))

"""ArduPilot parameter metadata frontend: ``*.pdef.xml`` (the apm.pdef.xml ground stations read) -> IR.

The file is what ArduPilot's param_parse.py emits::

    <paramfile><vehicles>/<libraries>
      <parameters name="BATT_">
        <param name="BATT_LOW_VOLT" humanName="..." documentation="..." user="Standard">
          <field name="Units">V</field> <field name="Range">0 30</field> <field name="Increment">0.1</field>
          <values><value code="0">None</value>...</values>           (or <field name="Values">0:None,...)
          <bitmask><bit code="0">...</bit>...</bitmask>             (or <field name="Bitmask">0:...,1:...)

Each <parameters> group becomes one Message ``params.<group>`` (trailing ``_`` dropped), each
<param> a Field named as the parameter (a vehicle's ``ArduCopter:NAME`` loses its prefix).
apm.pdef.xml has no type and no default, so two optional fields of our own are read:
``Type`` (float, int8, int16, int32; AP_Float... spellings too) and ``Default``. Without ``Type``
a parameter is an integer when it has Values or a Bitmask, or an integral Increment (and Range),
else float32. Other fields (Increment, User, RebootRequired...) are kept as annotations.
Parsed with expat for line numbers; DTDs and entities are refused.
"""

from __future__ import annotations

import math
import re
import xml.parsers.expat
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import SchemaError
from ..ir import (
    Constant,
    EnumDef,
    EnumEntry,
    EnumKind,
    Field,
    Location,
    Message,
    ParamsInfo,
    PrimitiveKind,
    PrimitiveType,
    Range,
    Schema,
    SourceFormat,
    units,
)
from ..text.files import display_path, read_text

__all__ = ["parse_dir", "parse_file"]

SUFFIX = ".pdef.xml"
MAX_NAME = 16  # a MAVLink PARAM_VALUE param_id holds 16 characters
_PARAM_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
_GROUP_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
_INT = re.compile(r"[+-]?[0-9]+")
_NUMBER = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_TYPES: dict[str, PrimitiveType] = {
    "float": PrimitiveType(PrimitiveKind.FLOAT, 32),
    "int8": PrimitiveType(PrimitiveKind.INT, 8),
    "int16": PrimitiveType(PrimitiveKind.INT, 16),
    "int32": PrimitiveType(PrimitiveKind.INT, 32),
}
_TYPE_ALIASES = {"ap_float": "float", "ap_int8": "int8", "ap_int16": "int16", "ap_int32": "int32", "float32": "float"}
# fields turned into IR facts rather than annotations
_STRUCTURAL = frozenset({"Type", "Units", "Range", "Default", "Values", "Bitmask"})


@dataclass
class _Node:
    tag: str
    attrs: dict[str, str]
    line: int
    children: list[_Node] = field(default_factory=list)
    text: str = ""


class _TreeBuilder:
    """A tiny element tree with line numbers; refuses DOCTYPE and ENTITY declarations."""

    def __init__(self, display: str) -> None:
        self.display = display
        self.parser = xml.parsers.expat.ParserCreate()
        p = self.parser
        p.SetParamEntityParsing(xml.parsers.expat.XML_PARAM_ENTITY_PARSING_NEVER)
        p.StartDoctypeDeclHandler = self._doctype
        p.EntityDeclHandler = self._entity
        p.StartElementHandler = self._start
        p.EndElementHandler = self._end
        p.CharacterDataHandler = self._chars
        self.stack: list[_Node] = []
        self.root: _Node | None = None

    def _doctype(self, *_: object) -> None:
        raise SchemaError(
            self.display, self.parser.CurrentLineNumber, "expected no DOCTYPE (apm.pdef.xml needs no DTD)"
        )

    def _entity(self, *_: object) -> None:
        raise SchemaError(self.display, self.parser.CurrentLineNumber, "expected no ENTITY declarations")

    def _start(self, tag: str, attrs: dict[str, str]) -> None:
        node = _Node(tag, dict(attrs), self.parser.CurrentLineNumber)
        if self.stack:
            self.stack[-1].children.append(node)
        else:
            self.root = node
        self.stack.append(node)

    def _end(self, tag: str) -> None:
        node = self.stack.pop()
        node.text = node.text.strip()

    def _chars(self, data: str) -> None:
        if self.stack:
            self.stack[-1].text += data

    def build(self, data: bytes) -> _Node:
        try:
            self.parser.Parse(data, True)
        except xml.parsers.expat.ExpatError as exc:
            message = xml.parsers.expat.errors.messages.get(exc.code, str(exc))
            raise SchemaError(self.display, exc.lineno, f"expected well-formed XML ({message})") from None
        assert self.root is not None  # expat rejects an empty document
        return self.root


def parse_file(path: Path, *, root: Path | None = None) -> Schema:
    """One apm.pdef.xml-style file: every <parameters> group in it."""
    display = display_path(path, root)
    data = read_text(path, display).encode("utf-8")
    doc = _TreeBuilder(display).build(data)
    messages = _File(display).messages(doc)
    return Schema(messages=tuple(sorted(messages, key=lambda m: m.qualified_name)), sources=(display,))


def parse_dir(root: Path) -> Schema:
    """Every ``*.pdef.xml`` below ``root``, in sorted path order."""
    if not root.is_dir():
        raise SchemaError(display_path(root, None), 0, f"expected a directory of {SUFFIX} files")
    schema = Schema()
    for path in sorted(root.rglob("*" + SUFFIX)):
        if path.is_file():
            schema = schema.merged(parse_file(path, root=root))
    seen: dict[str, Message] = {}
    for msg in schema.messages:
        if msg.qualified_name in seen:
            first = seen[msg.qualified_name].location
            raise SchemaError(
                msg.location.file,
                msg.location.line,
                f"expected one definition of {msg.qualified_name} (also at {first})",
            )
        seen[msg.qualified_name] = msg
    return Schema(messages=tuple(sorted(schema.messages, key=lambda m: m.qualified_name)), sources=schema.sources)


class _File:
    def __init__(self, display: str) -> None:
        self.display = display

    def error(self, node: _Node, message: str) -> SchemaError:
        return SchemaError(self.display, node.line, message)

    def loc(self, node: _Node) -> Location:
        return Location(self.display, node.line)

    def messages(self, doc: _Node) -> list[Message]:
        if doc.tag != "paramfile":
            raise self.error(doc, f"expected <paramfile> as the root element, got <{doc.tag}>")
        out: list[Message] = []
        names: dict[str, int] = {}
        for section in doc.children:
            if section.tag not in ("vehicles", "libraries"):
                raise self.error(section, f"expected <vehicles> or <libraries> in <paramfile>, got <{section.tag}>")
            for group in section.children:
                if group.tag != "parameters":
                    raise self.error(group, f"expected <parameters> in <{section.tag}>, got <{group.tag}>")
                msg = self.group(group, section.tag)
                if msg.name in names:
                    raise self.error(
                        group, f"expected one <parameters name=...> group {msg.name} (also line {names[msg.name]})"
                    )
                names[msg.name] = group.line
                out.append(msg)
        return out

    def group(self, node: _Node, section: str) -> Message:
        raw = node.attrs.get("name")
        if raw is None:
            raise self.error(node, 'expected a "name" attribute on <parameters>')
        name = raw.rstrip("_")
        if not _GROUP_NAME.fullmatch(name):
            raise self.error(node, f"expected a parameter group name (letters, digits, _), got {raw!r}")
        prefix = name + "_" if section == "libraries" else ""
        qualified = f"params.{name}"
        fields: list[Field] = []
        constants: list[Constant] = []
        enums: list[EnumDef] = []
        seen: dict[str, int] = {}
        for child in node.children:
            if child.tag != "param":
                raise self.error(child, f"expected <param> in <parameters>, got <{child.tag}>")
            f, enum, members = self.param(child, qualified, prefix)
            if f.name in seen:
                raise self.error(
                    child, f"expected each parameter once in group {name}: {f.name} is also at line {seen[f.name]}"
                )
            seen[f.name] = child.line
            fields.append(f)
            if enum is not None:
                enums.append(enum)
                constants.extend(members)
        return Message(
            name=name,
            qualified_name=qualified,
            format=SourceFormat.PARAMS,
            location=self.loc(node),
            doc=node.attrs.get("documentation", "").strip(),
            fields=tuple(fields),
            constants=tuple(constants),
            enums=tuple(enums),
            params=ParamsInfo(prefix=prefix, section=section),
        )

    def param(self, node: _Node, qualified: str, prefix: str) -> tuple[Field, EnumDef | None, list[Constant]]:
        raw = node.attrs.get("name")
        if raw is None:
            raise self.error(node, 'expected a "name" attribute on <param>')
        name = raw.split(":", 1)[1] if ":" in raw else raw  # ArduCopter:FRAME_CLASS -> FRAME_CLASS
        if not _PARAM_NAME.fullmatch(name) or len(name) > MAX_NAME:
            raise self.error(node, f"expected a parameter name of 1 to {MAX_NAME} letters, digits and _, got {raw!r}")
        fields: dict[str, _Node] = {}
        values: _Node | None = None
        bits: _Node | None = None
        for child in node.children:
            if child.tag == "field":
                key = child.attrs.get("name")
                if not key:
                    raise self.error(child, 'expected a "name" attribute on <field>')
                if key in fields:
                    raise self.error(
                        child, f"expected one <field name={key!r}> in {name} (also line {fields[key].line})"
                    )
                fields[key] = child
            elif child.tag == "values":
                values = child
            elif child.tag == "bitmask":
                bits = child
            else:
                raise self.error(child, f"expected <field>, <values> or <bitmask> in <param>, got <{child.tag}>")

        value_entries = self.entries(values, "value") if values is not None else None
        if value_entries is None and "Values" in fields:
            value_entries = self.pairs(fields["Values"], "Values")
        bit_entries = self.entries(bits, "bit") if bits is not None else None
        if bit_entries is None and "Bitmask" in fields:
            bit_entries = self.pairs(fields["Bitmask"], "Bitmask")
        if value_entries is not None and bit_entries is not None:
            raise self.error(node, f"expected Values or a Bitmask on {name}, not both")

        rng = self.range(fields["Range"]) if "Range" in fields else None
        ptype = self.type(fields, node, name, rng, value_entries, bit_entries)
        default = self.default(fields["Default"], ptype, rng, name) if "Default" in fields else None
        unit = unit_text = None
        if "Units" in fields and fields["Units"].text:
            unit_text = fields["Units"].text
            unit = units.lookup(unit_text) or units.opaque(unit_text)

        short = name[len(prefix) :] if prefix and name.startswith(prefix) and len(name) > len(prefix) else name
        enum_name = f"{qualified}.{short}"
        enum: EnumDef | None = None
        members: list[Constant] = []
        if value_entries is not None:
            enum = self.enum(enum_name, short, EnumKind.VALUE, value_entries, node, ptype)
        elif bit_entries is not None:
            for code, _, where in bit_entries:
                if not 0 <= code < ptype.bits:
                    raise SchemaError(
                        self.display, where, f"expected a bit number from 0 to {ptype.bits - 1} in {name}, got {code}"
                    )
            masks = [(1 << code, label, where) for code, label, where in bit_entries]
            enum = self.enum(enum_name, short, EnumKind.BITMASK, masks, node, ptype)
        if enum is not None:
            members = [Constant(e.name, ptype, e.value, e.doc, e.location) for e in enum.entries]

        annotations: list[tuple[str, str]] = []
        for attr in ("humanName", "user"):
            if attr in node.attrs:
                annotations.append((attr, node.attrs[attr]))
        for key, child in fields.items():
            if key not in _STRUCTURAL or (key in ("Values", "Bitmask") and enum is None):
                annotations.append((key, child.text))
        f = Field(
            name=name,
            type=ptype,
            location=self.loc(node),
            doc=node.attrs.get("documentation", "").strip(),
            unit=unit,
            unit_text=unit_text,
            range=rng,
            enums=(enum.name,) if enum is not None else (),
            default=default,
            annotations=tuple(annotations),
        )
        return f, enum, members

    def entries(self, node: _Node, tag: str) -> list[tuple[int, str, int]]:
        out = []
        for child in node.children:
            if child.tag != tag:
                raise self.error(child, f"expected <{tag}> in <{node.tag}>, got <{child.tag}>")
            code = child.attrs.get("code", "").strip()
            if not _INT.fullmatch(code):
                raise self.error(child, f'expected an integer code="..." on <{tag}>, got {code!r}')
            out.append((int(code), child.text, child.line))
        return out

    def pairs(self, node: _Node, what: str) -> list[tuple[int, str, int]]:
        """``0:None,1:Hold`` as written in a <field name="Values"> / "Bitmask"."""
        out = []
        for part in node.text.split(","):
            code, sep, label = part.partition(":")
            if not sep or not _INT.fullmatch(code.strip()):
                raise self.error(node, f"expected {what} as code:label pairs separated by commas, got {part.strip()!r}")
            out.append((int(code), label.strip(), node.line))
        return out

    def range(self, node: _Node) -> Range:
        parts = node.text.split()
        if len(parts) != 2 or not all(_NUMBER.fullmatch(p) for p in parts):
            raise self.error(node, f"expected Range as two numbers 'min max', got {node.text!r}")
        lo, hi = (_number(p) for p in parts)
        if lo > hi:
            raise self.error(node, f"expected Range min <= max, got {node.text!r}")
        return Range(minimum=lo, maximum=hi)

    def type(
        self,
        fields: dict[str, _Node],
        node: _Node,
        name: str,
        rng: Range | None,
        values: list[tuple[int, str, int]] | None,
        bits: list[tuple[int, str, int]] | None,
    ) -> PrimitiveType:
        if "Type" in fields:
            text = fields["Type"].text
            key = _TYPE_ALIASES.get(text.lower(), text.lower())
            if key not in _TYPES:
                raise self.error(fields["Type"], f"expected Type float, int8, int16 or int32, got {text!r}")
            ptype = _TYPES[key]
        else:
            ptype = _infer(fields, rng, values, bits)
        if ptype.kind is PrimitiveKind.INT and rng is not None:
            lo, hi = ptype.value_range or (0, 0)
            if not (isinstance(rng.minimum, int) and isinstance(rng.maximum, int)):
                raise self.error(fields["Range"], f"expected an integer Range for {ptype.name} parameter {name}")
            if rng.minimum < lo or rng.maximum > hi:
                raise self.error(fields["Range"], f"expected a Range within {ptype.name} ({lo}..{hi}) for {name}")
        if ptype.kind is PrimitiveKind.INT and values is not None:
            lo, hi = ptype.value_range or (0, 0)
            for code, _, where in values:
                if not lo <= code <= hi:
                    raise SchemaError(
                        self.display, where, f"expected a value code within {ptype.name} for {name}, got {code}"
                    )
        return ptype

    def default(self, node: _Node, ptype: PrimitiveType, rng: Range | None, name: str) -> int | float:
        text = node.text
        if ptype.kind is PrimitiveKind.INT:
            if not _INT.fullmatch(text):
                raise self.error(node, f"expected an integer Default for {ptype.name} parameter {name}, got {text!r}")
            value: int | float = int(text)
            lo, hi = ptype.value_range or (0, 0)
            if not lo <= value <= hi:
                raise self.error(node, f"expected a Default within {ptype.name} ({lo}..{hi}), got {text!r}")
        else:
            if not _NUMBER.fullmatch(text):
                raise self.error(node, f"expected a number as Default of {name}, got {text!r}")
            value = float(text)
        if rng is not None and not _within(value, rng):
            raise self.error(node, f"expected a Default within Range {rng.minimum} {rng.maximum}, got {text!r}")
        return value

    def enum(
        self,
        name: str,
        group: str,
        kind: EnumKind,
        items: list[tuple[int, str, int]],
        node: _Node,
        ptype: PrimitiveType,
    ) -> EnumDef:
        entries: list[EnumEntry] = []
        seen_codes: dict[int, int] = {}
        used: set[str] = set()
        for code, label, where in items:
            if code in seen_codes:
                raise SchemaError(
                    self.display,
                    where,
                    f"expected each code once in {group}: {code} is also at line {seen_codes[code]}",
                )
            seen_codes[code] = where
            stem = re.sub(r"[^0-9A-Za-z]+", "_", label).strip("_").upper() or str(code)
            entry_name = f"{group}_{stem}"
            while entry_name in used:
                entry_name += f"_{code}"
            used.add(entry_name)
            doc = label if kind is EnumKind.VALUE else f"{label} (bit {code.bit_length() - 1})"
            entries.append(EnumEntry(entry_name, code, doc, Location(self.display, where)))
        return EnumDef(name=name, kind=kind, entries=tuple(entries), location=self.loc(node))


def _number(text: str) -> int | float:
    return int(text) if _INT.fullmatch(text) else float(text)


def _within(value: float, rng: Range) -> bool:
    if rng.minimum is not None and value < rng.minimum:
        return False
    return not (rng.maximum is not None and value > rng.maximum)


def _infer(
    fields: dict[str, _Node],
    rng: Range | None,
    values: list[tuple[int, str, int]] | None,
    bits: list[tuple[int, str, int]] | None,
) -> PrimitiveType:
    """apm.pdef.xml states no type: integers are recognised by values, bits or whole steps."""
    inc = fields.get("Increment")
    integral_step = inc is not None and _INT.fullmatch(inc.text) is not None
    integral_range = rng is None or (isinstance(rng.minimum, int) and isinstance(rng.maximum, int))
    if bits is not None:
        top = max((code for code, _, _ in bits), default=0)
        return _TYPES["int8" if top < 7 else "int16" if top < 15 else "int32"]
    if values is None and not (integral_step and integral_range):
        return _TYPES["float"]
    codes = [code for code, _, _ in values or []]
    bounds = [] if rng is None else [float(b) for b in (rng.minimum, rng.maximum) if b is not None]
    span = [*codes, *bounds]
    for key in ("int8", "int16", "int32"):
        lo, hi = _TYPES[key].value_range or (0, 0)
        if all(lo <= v <= hi and not math.isinf(v) for v in span):
            return _TYPES[key]
    return _TYPES["float"]

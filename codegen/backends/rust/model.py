"""What the templates render of one message: its module path, struct fields with their doc comments
and defaults, the ``Option`` accessors of fields that can be unknown, enum accessors, constants,
codecs and checks. Every decision about the Rust shape is taken here; the templates only lay it out."""

from __future__ import annotations

from dataclasses import dataclass, field

from ...ir import ArrayType, CompositeType, Constant, Field, FieldType, Message, PrimitiveType, Schema, StringType
from .checks import FieldCheck, field_check
from .codecs import Codec, mavlink_codec, uorb_codec
from .docs import doc_lines
from .dronecan_codec import DronecanCodec, dronecan_codec
from .enums import TAKEN, EnumView, enum_view
from .naming import camel, field_ident, snake, upper
from .rules import RustRules, rust_rules
from .types import capacity, element, equals, float_literal, scalar, scalar_literal


def module_parts(qualified: str) -> list[str]:
    """``dronecan.uavcan.equipment.power.BatteryInfo`` -> its module path under ``crate``."""
    *space, name = qualified.split(".")
    return [snake(p) for p in space] + [snake(name)]


def type_path(qualified: str) -> str:
    """The struct's path (re-exported by its parent module)."""
    *space, name = qualified.split(".")
    return "crate::" + "::".join(snake(p) for p in space) + "::" + camel(name)


def rust_type(t: FieldType) -> str:
    if isinstance(t, PrimitiveType):
        return scalar(t)
    if isinstance(t, StringType):
        return f"[u8; {capacity(t)}]"
    if isinstance(t, CompositeType):
        return type_path(t.name)
    assert isinstance(t, ArrayType)
    return f"[{rust_type(t.element)}; {capacity(t)}]"


def default_value(f: Field, t: FieldType | None = None, index: int = 0) -> str:
    """The value a new message holds: the field's "unknown" sentinel where it has one, else zero."""
    t = f.type if t is None else t
    s = f.invalid
    if isinstance(t, PrimitiveType):
        marker = s.marker_at(index) if s is not None else None
        return scalar_literal(t, marker if marker is not None else 0)
    if isinstance(t, StringType):
        return f"[0; {capacity(t)}]"
    if isinstance(t, CompositeType):
        return f"{type_path(t.name)}::new()"
    assert isinstance(t, ArrayType)
    items = [default_value(f, t.element, i) for i in range(capacity(t))]
    if len(set(items)) == 1:
        return f"[{items[0]}; {capacity(t)}]"
    return "[" + ", ".join(items) + "]"


@dataclass(frozen=True)
class Member:
    ident: str
    rust: str
    doc: list[str]
    default: str
    length: str | None  # a dynamic array's length member


@dataclass(frozen=True)
class Accessor:
    """``fn ident(&self[, i]) -> Option<T>``: the value unless it is the field's "unknown" sentinel."""

    ident: str
    rust: str
    field: str
    indexed: bool
    unknown: str  # condition on `v` (and `i`) meaning unknown
    first: str | None  # MAVLink [X:]: element 0 at X makes every element unknown
    length: str | None


@dataclass(frozen=True)
class EnumAccessor:
    ident: str
    field: str
    type_path: str
    bitmask: bool
    convert: str  # the field's value in the enum's integer type


@dataclass(frozen=True)
class ConstantView:
    name: str
    rust: str
    value: str
    doc: list[str]


@dataclass(frozen=True)
class CheckUse:
    """One check as ``validate_into`` runs it: on a field of the message or of a message nested in it
    (``timestamp.usec``), through the check function of the message that defines the field."""

    path: str  # as problems name it
    target: str  # the value's expression (``self.timestamp.usec``)
    fn: str  # the check function's path
    check: FieldCheck
    held: str | None = None  # in a union: the condition that it holds this field (the others are not sent)

    @property
    def length(self) -> str:
        """A dynamic array's used length."""
        return f"{self.target}_len"

    @property
    def first_known(self) -> str | None:
        """MAVLink [X:]: the condition that element 0 is not X (the array's elements mean something)."""
        first = self.check.first
        return None if first is None else equals(first[0], first[1], f"{self.target}[0]", negate=True)


def check_uses(
    schema: Schema, msg: Message, path: str = "", target: str = "self.", depth: int = 0, held: str | None = None
) -> list[CheckUse]:
    """Every check of ``msg``'s fields and, path by path, of the messages nested in it (not in arrays);
    of a union's fields, the one it holds only, as the C library checks them."""
    module = "crate::" + "::".join(module_parts(msg.qualified_name)) + "::"
    union = msg.dronecan is not None and msg.dronecan.union
    out: list[CheckUse] = []
    for k, f in enumerate(msg.fields):
        if f.is_padding:
            continue
        mine = held
        if union:
            mine = " && ".join(c for c in (held, f"{target}union_tag == {k}") if c)
        ident = field_ident(f.name)
        c = field_check(schema, f, ident)
        if c is not None:
            out.append(CheckUse(path + f.name, target + ident, (module if depth else "") + c.fn_name, c, mine))
        elif isinstance(f.type, CompositeType) and depth < 8:
            inner = schema.message(f.type.name)
            out += check_uses(schema, inner, f"{path}{f.name}.", f"{target}{ident}.", depth + 1, mine)
    return out


@dataclass(frozen=True)
class UnionUse:
    """A DroneCAN union's tag checked by ``validate_into``: it must name one of the union's fields (the
    Python validator's ``union_field`` problem), the message's own or one nested in it."""

    path: str  # as problems name it (``pick.union_field``)
    target: str  # the tag's expression (``self.pick.union_tag``)
    count: int  # the union's fields
    held: str | None = None  # nested in a union: the condition that it holds the field


def union_uses(
    schema: Schema, msg: Message, path: str = "", target: str = "self.", depth: int = 0, held: str | None = None
) -> list[UnionUse]:
    """The union tags ``msg`` holds, its own and those of the messages nested in it (not in arrays)."""
    union = msg.dronecan is not None and msg.dronecan.union
    out = [UnionUse(path + "union_field", target + "union_tag", len(msg.fields), held)] if union else []
    for k, f in enumerate(msg.fields):
        if isinstance(f.type, CompositeType) and not f.is_padding and depth < 8:
            mine = " && ".join(c for c in (held, f"{target}union_tag == {k}" if union else None) if c) or None
            inner = schema.message(f.type.name)
            out += union_uses(schema, inner, f"{path}{f.name}.", f"{target}{field_ident(f.name)}.", depth + 1, mine)
    return out


@dataclass(frozen=True)
class MessageView:
    qualified: str
    name: str
    module: list[str]
    doc: list[str]
    members: list[Member]
    accessors: list[Accessor]
    enum_accessors: list[EnumAccessor]
    constants: list[ConstantView]
    enums: list[EnumView]
    checks: list[FieldCheck]  # the check functions the message's module defines
    uses: list[CheckUse]  # what its validate_into runs
    mavlink: Codec | None
    uorb: Codec | None
    dronecan: DronecanCodec | None
    msg: Message
    same: list[str] = field(default_factory=list)  # the sameness terms of PartialEq
    rules: RustRules = field(default_factory=RustRules)  # the cross-field rules, after the field checks
    unions: list[UnionUse] = field(default_factory=list)  # the union tags checked, after the field checks

    @property
    def max_problems(self) -> int:
        """Every value checked can break one rule, a dynamic array's length one more, and each
        cross-field rule once (once per index of its loop)."""
        checks = sum((u.check.count or 1) + (1 if u.check.dynamic else 0) for u in self.uses)
        return checks + len(self.unions) + self.rules.most


def _unknown(f: Field, t: PrimitiveType, ident: str) -> tuple[str, str | None] | None:
    """(condition on `v` (element `i`) meaning unknown, condition meaning element 0 makes the whole
    array unknown) for a field's values."""
    s = f.invalid
    if s is None:
        return None
    if s.first_decides:
        return "false", equals(t, s.value, f"self.{ident}[0]")
    if s.elements:
        conds = [f"i == {i} && {equals(t, v, 'v')}" for i, v in enumerate(s.elements) if v is not None]
        if len(conds) > 1:
            conds = [f"({c})" for c in conds]
        return " || ".join(conds) or "false", None
    return equals(t, s.value, "v"), None


def _accessor(f: Field, ident: str) -> Accessor | None:
    t = f.type
    if f.invalid is None:
        return None
    if isinstance(t, PrimitiveType):
        found = _unknown(f, t, ident)
        assert found is not None
        return Accessor(ident, scalar(t), f.name, False, found[0], None, None)
    if (
        isinstance(t, ArrayType)
        and isinstance(t.element, PrimitiveType)
        and (f.invalid.per_element or f.invalid.elements or f.invalid.first_decides)
    ):
        found = _unknown(f, t.element, ident)
        assert found is not None
        length = f"{ident}_len" if t.dynamic else None
        return Accessor(ident, scalar(t.element), f.name, True, found[0], found[1], length)
    return None


def _enum_accessor(msg: Message, f: Field, ident: str, views: dict[str, EnumView]) -> EnumAccessor | None:
    if len(f.enums) != 1 or not isinstance(f.type, PrimitiveType):
        return None
    view = views.get(f.enums[0])
    rust = scalar(f.type)
    if view is None or rust in ("bool", "f32", "f64", "u64"):
        return None
    local = any(e.name == f.enums[0] for e in msg.enums)
    path = view.name if local else "crate::" + snake(msg.format.value) + "::enums::" + view.name
    if view.bitmask:
        if rust == view.repr:
            convert = f"self.{ident}"
        elif _fits(rust, view.repr):
            convert = f"{view.repr}::from(self.{ident})"
        else:
            return None
        return EnumAccessor(f"{ident.rstrip('_')}_flags", f.name, path, True, convert)
    return EnumAccessor(f"{ident.rstrip('_')}_enum", f.name, path, False, f"i64::from(self.{ident})")


def _fits(narrow: str, wide: str) -> bool:
    """``From`` exists from ``narrow`` to ``wide`` (same signedness, wider or equal; or unsigned into wider signed)."""
    n, w = int(narrow[1:]), int(wide[1:])
    return (narrow[0] == wide[0] and n <= w) or (narrow[0] == "u" and wide[0] == "i" and n < w)


def _constant(c: Constant) -> ConstantView:
    v = c.value
    if isinstance(c.type, StringType) or isinstance(v, str):
        text = str(v).replace("\\", "\\\\").replace('"', '\\"')
        return ConstantView(upper(c.name), "&str", f'"{text}"', doc_lines(c.doc))
    rust = scalar(c.type)
    if rust in ("f32", "f64"):
        value = float_literal(float(v), rust)
    else:
        value = scalar_literal(c.type, v)
    return ConstantView(upper(c.name), rust, value, doc_lines(c.doc))


def _field_doc(f: Field) -> list[str]:
    notes = []
    t = element(f.type)
    if f.unit_text:
        notes.append(f"Unit: `{f.unit_text}`.")
    if f.invalid is not None:
        notes.append(f"Unknown: `{f.invalid.text}` (the accessor gives `None`).")
    if f.range is not None:
        low, high = f.range.minimum, f.range.maximum
        notes.append(f"Range: {'..' if low is None else low} to {'..' if high is None else high}.")
    if f.enums:
        notes.append("Values: " + ", ".join(f"`{e}`" for e in f.enums) + ".")
    if isinstance(t, PrimitiveType):
        notes.append(f"Wire type: `{t.name}`" + (" (MAVLink 2 extension)." if f.extension else "."))
    return doc_lines(f.doc, notes=(" ".join(notes),))


def message_view(schema: Schema, msg: Message, shared: dict[str, EnumView]) -> MessageView:
    idents = {f.name: field_ident(f.name) for f in msg.fields if not f.is_padding}
    taken = TAKEN | {camel(msg.name)}
    local = {e.name: enum_view(e, taken) for e in msg.enums}
    views = {**shared, **local}
    members: list[Member] = []
    same: list[str] = []
    if msg.dronecan is not None and msg.dronecan.union:
        names = ", ".join(f"{k} `{f.name}`" for k, f in enumerate(msg.fields))
        doc = [f"The field the union holds ({names}); only that one is sent."]
        members.append(Member("union_tag", "u8", doc, "0", None))
        same.append("self.union_tag == other.union_tag")
    for f in msg.fields:
        if f.is_padding:
            continue
        ident = idents[f.name]
        t = f.type
        length = f"{ident}_len" if isinstance(t, ArrayType) and t.dynamic else None
        members.append(Member(ident, rust_type(t), _field_doc(f), default_value(f), length))
        if isinstance(t, ArrayType) and t.dynamic:  # only the used elements are the message's data
            used, cap = f"{ident}_len", capacity(t)
            same.append(f"self.{used} == other.{used}")
            same.append(f"self.{ident}[..self.{used}.min({cap})].same(&other.{ident}[..other.{used}.min({cap})])")
        else:
            same.append(f"self.{ident}.same(&other.{ident})")
    fields = [f for f in msg.fields if not f.is_padding]
    accessors = [a for f in fields if (a := _accessor(f, idents[f.name])) is not None]
    enum_accessors = [e for f in fields if (e := _enum_accessor(msg, f, idents[f.name], views)) is not None]
    constants = [_constant(c) for c in msg.constants]
    checks = [c for f in fields if (c := field_check(schema, f, idents[f.name])) is not None]
    return MessageView(
        qualified=msg.qualified_name,
        name=camel(msg.name),
        module=module_parts(msg.qualified_name),
        doc=doc_lines(msg.doc, notes=(f"Schema: `{msg.qualified_name}` ({msg.location}).",)),
        members=members,
        accessors=accessors,
        enum_accessors=enum_accessors,
        constants=constants,
        enums=list(local.values()),
        checks=checks,
        uses=check_uses(schema, msg),
        mavlink=mavlink_codec(msg, idents),
        uorb=uorb_codec(msg, idents),
        dronecan=dronecan_codec(schema, msg, idents),
        msg=msg,
        same=same,
        rules=rust_rules(schema, msg),
        unions=union_uses(schema, msg),
    )


def shared_enums(schema: Schema, formats: tuple[str, ...]) -> dict[str, EnumView]:
    """The schema-level enum groups of the formats written (MAVLink's), by qualified name."""
    return {e.name: enum_view(e) for e in schema.enums if e.name.split(".")[0] in formats}

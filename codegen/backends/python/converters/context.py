"""What every rule emitter works with: the function being written, and facts about its fields.

A :class:`RuleContext` holds one direction of one mapping as it is written: the two sides (the
source endpoint's objects, read; the target's, written), the body lines so far, and the module
constants shared by both directions (:class:`ModuleConstants`). The emitter mixins of this
package (numeric, choices, cells, devicetree, messages, px4, px4_cells) build on it.

Emitters write each statement on one line (a call as :func:`call` spells it); the module is
formatted afterwards by ruff. Temporaries an emitter writes (``_v``, ``_c``, ...;
see :data:`TEMPORARIES`) get the rule's number as a suffix when emitted, so each has one type
across the function (mypy) and a reader can tell which rule made it.
"""

from __future__ import annotations

import math
import re
import struct
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from ....errors import BattgenError
from ....ir import (
    CONCEPTS_ENDPOINT,
    ArrayType,
    CompositeType,
    Concept,
    Endpoint,
    Field,
    FieldRef,
    Mapping,
    Message,
    PrimitiveKind,
    PrimitiveType,
    Rule,
    Schema,
    Unit,
    units,
)
from ....ir.fieldtypes import allowed_range, writable_ints
from ....ir.mapping_values import ConstantRef, Number, Value
from ....ir.rules import rule_ranges
from .. import naming
from ..formatting import LINE_LENGTH
from ..literals import float_literal, py_literal

FLT_EPS = 1.1920928955078125e-07
INDENT = "    "

TEMPORARIES = re.compile(r"\b_(?:v|w|c|p|x|n|m|b|e|f|s|a|l|t|ts|tb|tabs|cap|uv|hi|lo|ch|i)\b")
# f-strings (whose fields may name temporaries), other string literals (schema text: left as it is)
_QUOTED = r""""(?:[^"\\]|\\.)*"|'(?:[^'\\]|\\.)*'"""
_TOKENS = re.compile(rf"(\b[fF](?:{_QUOTED}))|({_QUOTED})|{TEMPORARIES.pattern}")


def f32(x: float) -> float:
    """``x`` rounded to the nearest float32, as PX4's C code holds it."""
    value: float = struct.unpack("<f", struct.pack("<f", x))[0]
    return value


@dataclass
class Side:
    """One end of a function: the endpoint's messages (or the concepts) and their variables."""

    endpoint: Endpoint | None  # None: the concepts
    messages: list[Message]
    names: list[str]  # variable per message (or the single concept-state variable)
    aliases: list[str]  # the endpoint's alias per message ("concepts" for the concepts)

    def var(self, qualified: str) -> str:
        if self.endpoint is None:
            return self.names[0]
        return self.names[self.endpoint.messages.index(qualified)]

    def alias(self, qualified: str) -> str:
        if self.endpoint is None:
            return self.aliases[0]
        return self.aliases[self.endpoint.messages.index(qualified)]

    def optional(self, qualified: str) -> bool:
        return self.endpoint is not None and self.endpoint.messages.index(qualified) > 0


class ModuleConstants:
    """The module-level constants of one generated mapping module, named for what they hold.

    A name asked for twice with the same value is one constant; with another value, the second
    gets the direction (``_FORWARD``) or a number appended.
    """

    def __init__(self) -> None:
        self.lines: dict[str, str] = {}  # name -> its assignment statement

    def add(self, name: str, value: object, direction: str, *, expression: str | None = None) -> str:
        """The constant ``name`` holding ``value`` (a literal) or ``expression`` (source text)."""
        candidates = [name, f"{name}_{direction.upper()}", *(f"{name}_{i}" for i in range(2, 100))]
        for candidate in candidates:
            text = f"{candidate} = {py_literal(value) if expression is None else expression}"
            if self.lines.setdefault(candidate, text) == text:
                return candidate
        raise BattgenError(f"too many constants named {name}")


def constant_name(*words: str) -> str:
    """A private module constant named by schema words: ``_CHEMISTRY_BY_TYPE``."""
    return "_" + "_".join(naming.identifier(w).upper().strip("_") or "X" for w in words)


class RuleContext:
    """One direction of one mapping being written; see the module docstring."""

    def unit_param(self, symbol: str | None, fallback: Unit | None) -> Unit | None:
        """The unit a rule names (``unit``, ``source_unit``, ...), else ``fallback``."""
        if symbol is None:
            return fallback
        unit = units.lookup(symbol)
        if unit is None:
            raise BattgenError(f"{self.mapping.name}: unknown unit {symbol!r}")
        return unit

    def __init__(
        self,
        schema: Schema,
        mapping: Mapping,
        concepts: dict[str, Concept],
        src: Side,
        dst: Side,
        direction: str,
        classes: dict[str, str],
        constants: ModuleConstants,
    ) -> None:
        self.schema = schema
        # the ranges rules state of single fields (MAVLink's battery_remaining: 0..100), by field: a converter
        # keeps to them as to the schema's own ranges (int_bounds)
        self.rule_ranges = {schema.field_at(m, name): rng for (m, name), rng in rule_ranges(schema).items()}
        self.mapping = mapping
        self.concepts = concepts
        self.src = src
        self.dst = dst
        self.direction = direction  # "forward" or "backward" (the function's name)
        self.backward = direction == "backward"
        self.classes = classes  # qualified message name -> the class's name in the module
        self.constants = constants
        self.member_cache: dict[str, dict[tuple[str, str], str]] = {}
        self.lines: list[str] = []
        self.inputs: list[str] = []  # extra keyword inputs (ocv_soc)
        self.read: set[tuple[str, str]] = set()
        self.written: set[tuple[str, str]] = set()
        self.bit_masks: dict[tuple[str, str], int] = {}
        self.pad = INDENT  # the indentation of the rule being written
        self.rule_number = 0

    # -- writing -------------------------------------------------------------------------------

    def _numbered(self, text: str) -> str:
        if not self.rule_number:  # the epilogue's temporaries keep their names
            return text

        def suffixed(m: re.Match[str]) -> str:
            return f"{m.group(0)}{self.rule_number}"

        def token(m: re.Match[str]) -> str:
            if m.group(1):  # an f-string: its fields are code
                return TEMPORARIES.sub(suffixed, m.group(1))
            return m.group(2) or suffixed(m)

        return _TOKENS.sub(token, text)

    def emit(self, *lines: str) -> None:
        """Body lines, indented relative to the rule's block."""
        self.lines.extend(self.pad + self._numbered(line) if line else "" for line in lines)

    def emit_call(self, head: str, args: list[str], nest: int = 0) -> None:
        """A call statement ``head(args)``, ``nest`` blocks into the rule's block."""
        self.emit(INDENT * nest + call(head, args))

    def emit_with_label(self, line: Callable[[str], str], label: str) -> None:
        """The line ``line(label)``; when that does not fit, the label goes into a variable (``_s``) first."""
        text = line(label)
        if len(self.pad) + len(self._numbered(text)) <= LINE_LENGTH:
            self.emit(text)
            return
        nest = text[: len(text) - len(text.lstrip())]
        self.emit(f"{nest}_s = {label}", line("_s"))

    def const(self, name: str, value: object, *, expression: str | None = None) -> str:
        return self.constants.add(name, value, self.direction, expression=expression)

    # -- names and facts -----------------------------------------------------------------------

    def msg(self, qualified: str) -> Message:
        return self.schema.message(qualified)

    def fld(self, ref: FieldRef) -> Field:
        return self.schema.field_at(ref.message, ref.field)

    def attr(self, ref: FieldRef) -> str:
        """The attribute (chain) of a field: ``voltage``, or a Cyphal path ``power.current.ampere``,
        ``temperature_min_max[1].kelvin`` (each step by the backend's naming rule)."""
        if ref.message == CONCEPTS_ENDPOINT:
            return naming.identifier(ref.field)
        head, *steps = ref.field.split(".")
        out = self.member(ref.message, head)
        t = self.msg(ref.message).field(head).type
        for step in steps:
            if isinstance(t, ArrayType):
                out += f"[{int(step)}]"
                t = t.element
            else:
                assert isinstance(t, CompositeType), ref
                out += "." + self.member(t.name, step)
                t = self.msg(t.name).field(step).type
        return out

    def member(self, message: str, field: str) -> str:
        """The attribute of a message's field, by the backend's one naming rule."""
        names = self.member_cache.get(message)
        if names is None:
            msg = self.msg(message)
            names = naming.member_names(msg, naming.module_classes(self.schema, naming.module_path(msg)))
            self.member_cache[message] = names
        return names[("field", field)]

    def s(self, ref: FieldRef) -> str:
        """A source value (and note that it is read)."""
        self.read.add((ref.message, ref.field))
        self.read.add((ref.message, ref.field.split(".")[0]))  # a path reads its top-level field
        return f"{self.src.var(ref.message)}.{self.attr(ref)}"

    def t(self, ref: FieldRef) -> str:
        """A target attribute (and note that it is written)."""
        self.written.add((ref.message, ref.field))
        self.written.add((ref.message, ref.field.split(".")[0]))
        return f"{self.dst.var(ref.message)}.{self.attr(ref)}"

    def label(self, ref: FieldRef) -> str:
        """The loss report's name of a field: ``qualified.message.field``."""
        return py_literal(f"{ref.message}.{ref.field}")

    def constant_value(self, name: str, refs: Iterable[FieldRef]) -> int | float | bool | str:
        """A constant by name, looked up in the messages a rule uses, then in dialect enums."""
        for ref in refs:
            if ref.message != CONCEPTS_ENDPOINT:
                # the message's own constants, then those of the nested type declaring the field (UDRAL's Error)
                for c in (*self.msg(ref.message).constants, *self.schema.owner_at(ref.message, ref.field).constants):
                    if c.name == name:
                        return c.value
        for e in self.schema.enums:
            for entry in e.entries:
                if entry.name == name:
                    return entry.value
        raise BattgenError(f"{self.mapping.name}: no constant {name!r}")

    def value_of(self, value: Value | None, refs: Iterable[FieldRef]) -> object:
        """A parameter as a Python value: named constants looked up."""
        if isinstance(value, ConstantRef):
            return self.constant_value(value.name, refs)
        return value

    def mask(self, name: ConstantRef, refs: Iterable[FieldRef]) -> int:
        """A constant as a mask: bit masks as they are, bit indices (uORB FAULT_*) as 1 << i."""
        value = self.constant_value(name.name, refs)
        for ref in refs:
            if ref.message == CONCEPTS_ENDPOINT:
                continue
            for e in self.msg(ref.message).enums:
                if any(x.name == name.name for x in e.entries) and e.kind.value == "bit_index":
                    return 1 << int(value)
        return int(value)

    def markers(self, f: Field, unknown: tuple[Number, ...]) -> list[float | int]:
        """The values meaning "unknown" for a field: its IR sentinel, then the rule's own (each once)."""
        out: list[float | int] = []
        for m in ([f.invalid.value] if f.invalid is not None else []) + list(unknown):
            if not any(_same(m, seen) for seen in out):
                out.append(m)
        return out

    def known_test(self, var: str, marks: list[float | int]) -> list[str]:
        """Conditions that ``var`` is none of ``marks`` (NaN by ``var == var``)."""
        return [f"{var} == {var}" if _nan(m) else f"{var} != {py_literal(m)}" for m in marks]

    def format_and_concept(self, rule: Rule) -> tuple[FieldRef, FieldRef]:
        """(the format field, the concept) of a rule relating one of each, whichever side is which."""
        fmt, con = rule.sources[0], rule.targets[0]
        if fmt.message == CONCEPTS_ENDPOINT:
            fmt, con = con, fmt
        return fmt, con

    # -- storing values as fields hold them ----------------------------------------------------

    def prim(self, f: Field) -> PrimitiveType | None:
        """The primitive type of a field, or of its elements."""
        t = f.type
        while isinstance(t, ArrayType):
            t = t.element
        return t if isinstance(t, PrimitiveType) else None

    def is_float(self, f: Field) -> bool:
        p = self.prim(f)
        return p is not None and p.kind is PrimitiveKind.FLOAT

    def marker_literal(self, f: Field, mark: float | int) -> str:
        return float_literal(mark) if self.is_float(f) else py_literal(int(mark))

    def store(self, f: Field, expr: str, label: str, hi: Number | None = None, marks: tuple[Number, ...] = ()) -> str:
        """``expr`` (a float) as the field holds it: float16/float32, bool, or a rounded integer clamped into
        :meth:`int_bounds` (``marks``: the rule's own unknown values, beside the field's sentinel)."""
        p = self.prim(f)
        if p is None:
            return expr
        if p.kind is PrimitiveKind.FLOAT:
            if p.bits == 16:
                return call("_r.f16", [expr, "rep", label])
            if p.bits == 32:
                return call("_r.f32", [expr])
            return expr
        if p.kind is PrimitiveKind.BOOL:
            return f"bool({expr})"
        if p.value_range is None:
            return expr
        lo, top = self.int_bounds(f, p, hi, self.markers(f, marks))
        return call("_r.to_int", [expr, py_literal(lo), py_literal(top), "rep", label])

    def int_bounds(self, f: Field, p: PrimitiveType, hi: Number | None, marks: list[float | int]) -> tuple[int, int]:
        """The integers a converter may write into an integer field: its type's, within the schema's range, the
        rule's ``valid_max`` and a validation rule's ``lo <= f <= hi``, less a sentinel at either end -- a value
        clamped onto it would read as unknown (a 400 degC temperature as MAVLink's INT16_MAX, a charge of -5 %
        as -1). What validate allows, so a clamp never writes what validate refuses."""
        rng = allowed_range(p, f.range).intersect(self.rule_ranges.get(f))
        return writable_ints(p, rng, hi, marks)

    def store_c(self, f: Field, expr: str, label: str) -> str:
        """A C assignment of a float32 value to the field's type, then DroneCAN saturation."""
        p = self.prim(f)
        if p is None:
            raise BattgenError(f"{self.mapping.name}: {f.name} is not a number")
        if p.kind is PrimitiveKind.FLOAT:
            return call("_r.f16", [expr, "rep", label]) if p.bits == 16 else expr
        if p.kind is PrimitiveKind.BOOL:
            return f"bool({expr})"
        signed = p.kind is PrimitiveKind.INT
        storage = next(b for b in (8, 16, 32, 64) if b >= p.bits)
        out = call("_r.c_float_to_int", [expr, str(storage), str(signed), "rep", label])
        if storage != p.bits:
            lo, hi = p.value_range or (0, 0)
            return call("_r.saturate", [out, str(int(lo)), str(int(hi))])
        return out

    def px4_read(self, ref: FieldRef, expr: str | None = None) -> str:
        """A source value as PX4 holds it in a C float: a DroneCAN float16 as it came off the wire."""
        value = expr or self.s(ref)
        p = self.prim(self.fld(ref))
        if p is not None and p.kind is PrimitiveKind.FLOAT and p.bits == 16:
            return f'_r.f16(float({value}), None, "")'
        return f"_r.f32(float({value}))"

    def emit_assign(self, target: str, value: str, nest: int = 0) -> None:
        """``target = value``, ``nest`` blocks into the rule's block."""
        self.emit(f"{INDENT * nest}{target} = {value}")


def call(func: str, args: list[str]) -> str:
    """The call expression ``func(args)``."""
    return f"{func}({', '.join(args)})"


def factor(frm: Unit | None, to: Unit | None) -> tuple[float, float]:
    """(multiplier, addend) between two units; none when either is unknown."""
    if frm is None or to is None:
        return 1.0, 0.0
    return frm.factor_to(to)


def affine(expr: str, mul: float, add: float) -> str:
    out = expr
    if mul != 1.0:
        out = f"{out} * {float_literal(mul)}"
    if add != 0.0:
        out = f"{out} + {float_literal(add)}"
    return out


def array_type(f: Field) -> ArrayType:
    if not isinstance(f.type, ArrayType):
        raise BattgenError(f"expected an array field, got {f.name!r}")
    return f.type


def _nan(value: object) -> bool:
    return isinstance(value, float) and math.isnan(value)


def _same(a: float | int, b: float | int) -> bool:
    return (_nan(a) and _nan(b)) or a == b

"""The engine of ``battgen vectors``: JSON conformance vectors of one converter, for other projects
(autopilots, SDKs, ground stations) to test their own converters against ours.

A vector is an input record of the source side, the output our generated converter gives for it
under a policy, and the loss report it writes. The set is made from the schemas, not by hand: a
*baseline* record (every field known, inside its range), then for every field of every source
message the edges a converter must get right -- the field at its "unknown" sentinel, NaN, the
ends of its range and of its type, a value beyond the range, every entry of its enums (each bit of
a bitmask), arrays empty, partly and fully filled, a sentinel inside an array. Each vector says
which field and which edge it exercises; ``coverage`` lists, per field, the edges written, so a
consumer sees that every mapping rule's inputs were varied. Floats keep the JSON spellings of
:mod:`codegen.ir.numbers` ("NaN", "Infinity").
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Iterator, Mapping
from typing import Any, cast

from ...errors import BattgenError
from ...inputs.records import Record
from ...ir import EnumKind, Schema
from ...ir.numbers import to_json_data
from ..schemas.package import bundled_schemas, load_schemas
from .convert import Conversion

FORMAT_VERSION = 1
SIDES = ("dronecan", "uorb", "uorb_v0", "mavlink")  # sources with message fields to vary
_INT_BITS = {"int": True, "uint": False}
_FLOAT32_MAX = 3.4028234663852886e38


@dataclasses.dataclass(frozen=True)
class FieldSpec:
    """What the vectors need to know of one source field (from the generated class's metadata)."""

    alias: str  # the message's alias within the side (info, aux, status, msg)
    name: str
    base: str  # element type: float32, uint16, bool, uint8 (char arrays: uint8)
    count: int | None  # None: a scalar; else the fixed length or the bound of a variable array
    variable: bool
    invalid: float | int | None
    per_element: bool
    minimum: float | None
    maximum: float | None
    enums: tuple[str, ...]
    default: object = None  # a composite field (a DSDL Timestamp): its default, as plain data


def _primitive(base: str) -> bool:
    return base == "bool" or _type_range(base) is not None or base in ("float64", "char", "string")


def _parse_type(text: str) -> tuple[str, int | None, bool]:
    base, bracket, rest = text.partition("[")
    if not bracket:
        return base, None, False
    inner = rest[: rest.index("]")]
    if inner.startswith("<="):
        return base, int(inner[2:]), True
    return base, (int(inner) if inner else 255), not inner


def field_specs(conversion: Conversion) -> list[FieldSpec]:
    """The source side's fields, message by message."""
    out = []
    for alias, cls in conversion.source.items:
        blank = cast(Any, cls)()
        for f in dataclasses.fields(cls):  # type: ignore[arg-type]
            m = f.metadata
            base, count, variable = _parse_type(str(m.get("type", "")))
            if not _primitive(base):
                value = getattr(blank, f.name)
                plain = [v.to_dict() for v in value] if isinstance(value, list) else value.to_dict()
                out.append(FieldSpec(alias, f.name, base, count, variable, None, False, None, None, (), plain))
                continue
            out.append(
                FieldSpec(
                    alias,
                    f.name,
                    base,
                    count,
                    variable,
                    m.get("invalid"),
                    bool(m.get("per_element")),
                    m.get("minimum"),
                    m.get("maximum"),
                    tuple(m.get("enums", ())),
                )
            )
    return out


def _type_range(base: str) -> tuple[float, float] | None:
    for prefix, signed in _INT_BITS.items():
        if base.startswith(prefix) and base[len(prefix) :].isdigit():
            bits = int(base[len(prefix) :])
            return (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if signed else (0, (1 << bits) - 1)
    if base == "float16":
        return (-65504.0, 65504.0)
    if base == "float32":
        return (-_FLOAT32_MAX, _FLOAT32_MAX)
    return None


def _is_float(base: str) -> bool:
    return base.startswith("float")


def _known(spec: FieldSpec) -> float | int | bool:
    """A known, unremarkable value: inside the range, away from the sentinel."""
    if spec.base == "bool":
        return True
    lo, hi = spec.minimum, spec.maximum
    if lo is not None and hi is not None:
        value: float = (lo + hi) / 2
    elif lo is not None:
        value = lo + 1
    else:
        value = 3.5 if _is_float(spec.base) else 3
    if not _is_float(spec.base):
        value = int(value)
        if spec.invalid is not None and value == spec.invalid:
            value += 1
    elif spec.invalid is not None and value == spec.invalid:
        value += 0.5
    return value


def _filled(spec: FieldSpec, element: object, n: int | None = None) -> object:
    if spec.count is None:
        return element
    length = spec.count if n is None else n
    return [element] * length


def baseline(specs: list[FieldSpec]) -> dict[str, dict[str, object]]:
    """A record of every source message: each field known (arrays: three known elements, the rest
    at their sentinel; an enum field at its first entry)."""
    out: dict[str, dict[str, object]] = {}
    for s in specs:
        if s.default is not None:
            value: object = s.default
        elif s.base == "uint8" and s.variable and s.enums == () and s.name.endswith("name"):
            value = []  # a text field (model_name): left empty
        elif s.count is None:
            value = _known(s)
        elif s.variable:
            value = [_known(s)] * min(3, s.count)
        else:
            pad = s.invalid if s.per_element and s.invalid is not None else 0
            value = [_known(s)] * min(3, s.count) + [pad] * (s.count - min(3, s.count))
        out.setdefault(s.alias, {})[s.name] = value
    return out


def edges(spec: FieldSpec, schema: Schema) -> Iterator[tuple[str, object]]:
    """(edge name, value) for one field (none for a composite field: it keeps its default)."""
    if spec.default is not None:
        return
    known = _known(spec)
    if spec.invalid is not None:
        yield "unknown", _filled(spec, spec.invalid)
    if _is_float(spec.base):
        if spec.invalid is None or not (isinstance(spec.invalid, float) and math.isnan(spec.invalid)):
            yield "nan", _filled(spec, math.nan)
        yield "zero", _filled(spec, 0.0)
        yield "negative", _filled(spec, -abs(float(known)) - 1.0)
    if spec.minimum is not None:
        yield "minimum", _filled(spec, spec.minimum)
        yield "below-minimum", _filled(spec, spec.minimum - 1)
    if spec.maximum is not None:
        yield "maximum", _filled(spec, spec.maximum)
        yield "above-maximum", _filled(spec, spec.maximum + 1)
    limits = _type_range(spec.base)
    if limits is not None:
        yield "type-lowest", _filled(spec, limits[0])
        yield "type-highest", _filled(spec, limits[1])
    if spec.base == "bool":
        yield "false", _filled(spec, False)
    for name in spec.enums:
        enum = schema.enum(name)
        for entry in enum.entries:
            value = 1 << entry.value if enum.kind is EnumKind.BIT_INDEX else entry.value
            yield f"{enum.short_name}.{entry.name}", _filled(spec, value)
    if spec.count is not None:
        element = known
        if spec.variable:
            yield "array-empty", []
            yield "array-one", [element]
        yield "array-full", [element] * spec.count
        if spec.invalid is not None and spec.per_element and spec.count >= 3:
            yield "array-sentinel-inside", [element, spec.invalid, element] + [spec.invalid] * (spec.count - 3)


@functools.cache
def _bundled_schema() -> Schema:
    """The bundled schemas' IR (enum entries), read once per process."""
    return load_schemas(bundled_schemas())


class VectorWriter:
    """Makes the vectors of one converter under one policy."""

    def __init__(self, source: str, target: str, policy: str) -> None:
        self.conversion = Conversion(None, source, target, policy)  # the bundled schemas' package
        if self.conversion.source_name not in SIDES:
            raise BattgenError(
                f"vectors are made for message sides ({', '.join(SIDES)}); {self.conversion.source_name!r} is not one"
            )
        self.specs = field_specs(self.conversion)

    def _input(self, record: Mapping[str, Mapping[str, object]]) -> dict[str, object]:
        """The input as a user writes it: a bare object for a one-message side."""
        if len(self.conversion.source.items) > 1:
            return {alias: dict(values) for alias, values in record.items()}
        return dict(record[self.conversion.source.items[0][0]])

    def convert(self, data: dict[str, object]) -> dict[str, object]:
        """Our converter on one input: the output and loss report, or the error it gives."""
        c = self.conversion
        try:
            objs = c.source.build(Record(0, 0, data, "vector"))
            report = c.module.LossReport()
            result = c.func(*objs, policy=c.policy, report=report)
            return {"output": c.target.to_plain(result), "loss": report.to_dict()}
        except (BattgenError, ValueError, TypeError, AttributeError) as exc:
            return {"error": str(exc)}

    def document(self) -> dict[str, object]:
        c = self.conversion
        schema = _bundled_schema()
        base = baseline(self.specs)
        vectors = [self._vector("baseline", "", "", base)]
        coverage: dict[str, list[str]] = {}
        for spec in self.specs:
            qualified = f"{spec.alias}.{spec.name}"
            if spec.default is not None:  # a composite (DSDL Timestamp): at its default in every vector
                coverage[qualified] = ["default"]
                continue
            for edge, value in edges(spec, schema):
                record = {alias: dict(values) for alias, values in base.items()}
                record[spec.alias][spec.name] = value
                vectors.append(self._vector(f"{qualified}/{edge}", qualified, edge, record))
                coverage.setdefault(qualified, []).append(edge)
        sides = {
            side.name: [getattr(cls, "QUALIFIED_NAME", cls.__name__) for _, cls in side.items]
            for side in (c.source, c.target)
        }
        return {
            "battgen_vectors": FORMAT_VERSION,
            "source": c.source_name,
            "target": c.target_name,
            "policy": c.policy,
            "messages": sides,
            "inputs": "a bare object for a one-message side, else one object per message alias",
            "numbers": "NaN and the infinities are the strings 'NaN', 'Infinity', '-Infinity'",
            "coverage": coverage,
            "vectors": vectors,
        }

    def _vector(self, vid: str, field: str, edge: str, record: Mapping[str, Mapping[str, object]]) -> dict[str, object]:
        data = self._input(record)
        out: dict[str, object] = {"id": vid}
        if field:
            out["field"], out["edge"] = field, edge
        out["input"] = to_json_data(data)
        out.update(cast(dict[str, object], to_json_data(self.convert(data))))
        return out


def vectors_document(source: str, target: str, policy: str) -> dict[str, object]:
    """The vectors document of one converter under one policy."""
    return VectorWriter(source, target, policy).document()

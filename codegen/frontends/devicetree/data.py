"""The two data files the devicetree frontend reads: types.yaml and property-units.yaml.

They sit at the schema root (schemas/devicetree/); a copy ships in ``packaged/`` beside this
module for roots that lack them -- or hold dt-schema's own files of the same names, which have
another layout (ours carry a ``format:`` marker).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

from ...errors import SchemaError
from ...ir import Unit, units
from ...text.files import display_path
from ...text.limits import read_schema_text
from ...text.yaml_lines import YList, YMap, load

TYPES_FILE = "types.yaml"
UNITS_FILE = "property-units.yaml"
DATA_FILES = frozenset({TYPES_FILE, UNITS_FILE})
PACKAGED = Path(__file__).resolve().parent / "packaged"
_TYPES_FORMAT = "battgen-devicetree-types/1"
_UNITS_FORMAT = "battgen-devicetree-property-units/1"
_VALUES = frozenset({"flag", "uint", "int", "string", "phandle"})
_SHAPES = frozenset({"scalar", "array", "matrix"})


@dataclass(frozen=True)
class TypeDef:
    """One types.yaml definition: element kind and width, and the shape of the value."""

    name: str
    value: str
    bits: int
    shape: str
    min_items: int | None = None
    inner_max_items: int | None = None
    unique: bool = False
    doc: str = ""


@dataclass(frozen=True)
class UnitRule:
    suffix: str
    type: str
    unit: Unit
    unit_text: str  # the suffix without its dash, as a property name spells the unit
    unless: re.Pattern[str] | None = None


@dataclass(frozen=True)
class DtData:
    types: dict[str, TypeDef]
    rules: tuple[UnitRule, ...]  # longest suffix first, so -micro-ohms wins over -ohms
    names: dict[str, UnitRule]

    def unit_rule(self, name: str) -> UnitRule | None:
        """The rule for a property name (or a pattern property's regex, its trailing '$' ignored)."""
        if name in self.names:
            return self.names[name]
        stem = name[:-1] if name.endswith("$") else name
        for rule in self.rules:
            if stem.endswith(rule.suffix) and not (rule.unless and rule.unless.search(stem)):
                return rule
        return None


def _ours(path: Path, marker: str) -> bool:
    try:
        head = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return False
    return f"format: {marker}" in head


def _pick(root: Path | None, name: str, marker: str) -> Path:
    if root is not None and _ours(root / name, marker):
        return root / name
    return PACKAGED / name


def load_data(root: Path | None) -> DtData:
    """The data for a schema root (cached per file pair)."""
    return _load(_pick(root, TYPES_FILE, _TYPES_FORMAT), _pick(root, UNITS_FILE, _UNITS_FORMAT), root)


@lru_cache(maxsize=8)
def _load(types_path: Path, units_path: Path, root: Path | None) -> DtData:
    types = _load_types(types_path, display_path(types_path, root))
    rules, names = _load_units(units_path, display_path(units_path, root), types)
    return DtData(types=types, rules=rules, names=names)


def _mapping(value: Any, display: str, line: int, what: str) -> YMap:
    if not isinstance(value, YMap):
        raise SchemaError(display, line, f"expected {what} to be a mapping")
    return value


def _load_types(path: Path, display: str) -> dict[str, TypeDef]:
    doc = _mapping(load(read_schema_text(path, display), display), display, 1, "the file")
    defs = _mapping(doc.get("definitions"), display, doc.line_of("definitions"), "'definitions'")
    out: dict[str, TypeDef] = {}
    for name, spec in defs.items():
        line = defs.line_of(name)
        spec = _mapping(spec, display, line, f"definition {name!r}")
        value, bits, shape = spec.get("value"), spec.get("bits"), spec.get("shape")
        if value not in _VALUES or shape not in _SHAPES or not isinstance(bits, int):
            raise SchemaError(display, line, f"expected {name!r} to give value ({sorted(_VALUES)}), bits and shape")
        out[str(name)] = TypeDef(
            name=str(name),
            value=str(value),
            bits=bits,
            shape=str(shape),
            min_items=spec.get("min_items"),
            inner_max_items=spec.get("inner_max_items"),
            unique=bool(spec.get("unique", False)),
            doc=str(spec.get("doc", "")),
        )
    return out


def _rule(entry: Any, key: str, display: str, line: int, types: dict[str, TypeDef]) -> UnitRule:
    entry = _mapping(entry, display, line, "a unit rule")
    text, type_name, symbol = entry.get(key), entry.get("type"), entry.get("unit")
    if not isinstance(text, str) or type_name not in types or not isinstance(symbol, str):
        raise SchemaError(display, entry.line, f"expected {{{key}, type (a types.yaml definition), unit}}")
    unit = units.lookup(symbol)
    if unit is None:
        raise SchemaError(display, entry.line, f"expected a unit codegen.ir.units knows, not {symbol!r}")
    unless = entry.get("unless")
    try:
        pattern = re.compile(unless) if isinstance(unless, str) else None
    except re.error:
        raise SchemaError(display, entry.line, "expected 'unless' to be a regular expression") from None
    spelled = text.lstrip("-") if key == "suffix" else text.rsplit("-", 1)[-1]
    return UnitRule(suffix=text, type=str(type_name), unit=unit, unit_text=spelled, unless=pattern)


def _load_units(
    path: Path, display: str, types: dict[str, TypeDef]
) -> tuple[tuple[UnitRule, ...], dict[str, UnitRule]]:
    doc = _mapping(load(read_schema_text(path, display), display), display, 1, "the file")
    suffixes, names = doc.get("suffixes"), doc.get("names", YList())
    if not isinstance(suffixes, YList) or not isinstance(names, YList):
        raise SchemaError(display, doc.line_of("suffixes"), "expected 'suffixes' and 'names' to be lists")
    rules = [_rule(e, "suffix", display, suffixes.line, types) for e in suffixes]
    rules.sort(key=lambda r: -len(r.suffix))  # stable: equal lengths keep file order
    exact = {r.suffix: r for r in (_rule(e, "name", display, names.line, types) for e in names)}
    return tuple(rules), exact

"""The namespaces below a DSDL root: finding the root, reading each definition once, following references.

A definition's full name comes from its path below the root (``uavcan/equipment/power/
1092.BatteryInfo.uavcan`` is ``uavcan.equipment.power.BatteryInfo``, default id 1092); a composite
type it references is looked up by name in the same tree, so every reference resolves once loaded.
"""

from __future__ import annotations

from pathlib import Path

from ...errors import SchemaError
from ...text.files import display_path
from ...text.limits import read_schema_text
from .definitions import ArrayT, RefT, TypeDef
from .names import check_full_name, split_file_name, valid_namespace_component
from .signature import dsdl_signature
from .syntax import parse_source

_ROOT_MARKERS = (("dsdl_specs", "dsdl"), ("dronecan",))


def find_root(path: Path) -> Path:
    """The DSDL root of a file given without one (the rules are in the package docstring)."""
    parents = list(path.resolve().parents)
    for markers in _ROOT_MARKERS:
        found = None
        for depth, ancestor in enumerate(parents):
            between = parents[:depth]
            if not between or not all(valid_namespace_component(p.name) for p in between):
                continue
            if ancestor.name in markers:
                found = ancestor  # keep walking up: the top-most one wins
        if found is not None:
            return found
    return parents[1] if len(parents) > 1 else parents[0]


class Namespaces:
    """The definitions below one DSDL root, each file read once, references followed on demand."""

    def __init__(self, root: Path) -> None:
        self.root = root
        self._abs_root = root.resolve()
        self.defs: dict[str, TypeDef] = {}
        self._by_path: dict[Path, TypeDef] = {}
        self._loading: list[str] = []

    def load_path(self, path: Path) -> TypeDef:
        resolved = path.resolve()
        if resolved in self._by_path:
            return self._by_path[resolved]
        display = display_path(path, self.root)
        try:
            relative = resolved.relative_to(self._abs_root)
        except ValueError:
            raise SchemaError(display, 0, f"expected the file below the DSDL root {self.root.as_posix()}") from None
        parsed_name = split_file_name(path.name)
        if parsed_name is None:
            raise SchemaError(display, 0, "expected a file name like [<id>.]<Name>[.<major>.<minor>].uavcan")
        default_id, short, version = parsed_name
        namespace = ".".join(relative.parts[:-1])
        full_name = f"{namespace}.{short}" if namespace else short
        check_full_name(full_name, display, 0)
        if full_name in self.defs:
            other = self.defs[full_name].file
            raise SchemaError(display, 0, f"expected one definition of {full_name}, also defined in {other}")
        if full_name in self._loading:
            chain = " -> ".join([*self._loading, full_name])
            raise SchemaError(display, 0, f"expected no recursive type references: {chain}")
        text = read_schema_text(path, display)
        td = parse_source(text, file=display, full_name=full_name, default_id=default_id, version=version)
        self._loading.append(full_name)
        try:
            self._load_references(td)
        finally:
            self._loading.pop()
        self.defs[full_name] = td
        self._by_path[resolved] = td
        return td

    def _load_references(self, td: TypeDef) -> None:
        for section in td.sections:
            for f in section.fields:
                ref = f.type.element if isinstance(f.type, ArrayT) else f.type
                if not isinstance(ref, RefT) or ref.full_name in self.defs:
                    continue
                if ref.full_name in self._loading:
                    chain = " -> ".join([*self._loading, ref.full_name])
                    raise SchemaError(td.file, f.line, f"expected no recursive type references: {chain}")
                location = self._locate(ref.full_name, td.file, f.line)
                nested = self.load_path(location)
                if nested.is_service:
                    raise SchemaError(td.file, f.line, f"expected a message type, {ref.full_name} is a service")

    def _locate(self, full_name: str, file: str, line: int) -> Path:
        namespace, _, short = full_name.rpartition(".")
        directory = self.root.joinpath(*namespace.split("."))
        candidates = []
        if directory.is_dir():
            for entry in sorted(directory.iterdir()):
                parsed = split_file_name(entry.name)
                if parsed is not None and parsed[1] == short and entry.is_file():
                    candidates.append(entry)
        if not candidates:
            raise SchemaError(
                file,
                line,
                f"unresolvable type {full_name}: expected a definition file for it in {directory.as_posix()}",
            )
        if len(candidates) > 1:
            names = ", ".join(c.name for c in candidates)
            raise SchemaError(file, line, f"expected one definition file for {full_name}, found {names}")
        return candidates[0]

    def check_unique_ids(self) -> None:
        """Two types may share a default id (per kind) only with the same DSDL signature."""
        seen: dict[tuple[bool, int], TypeDef] = {}
        for name in sorted(self.defs):
            td = self.defs[name]
            if td.default_id is None:
                continue
            key = (td.is_service, td.default_id)
            first = seen.setdefault(key, td)
            if first is not td and dsdl_signature(first) != dsdl_signature(td):
                raise SchemaError(
                    td.file, 0, f"expected a unique data type id; {td.default_id} is used by {first.file}"
                )

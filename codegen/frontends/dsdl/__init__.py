"""DroneCAN (UAVCAN v0) DSDL frontend: ``*.uavcan`` definitions -> IR.

Layout: a DSDL *root* directory holds root namespaces (``root/uavcan/equipment/power/
1092.BatteryInfo.uavcan`` is ``uavcan.equipment.power.BatteryInfo`` with default data type id
1092). ``parse_dir(root)`` parses every ``*.uavcan`` below root; ``parse_file(path, root=...)``
parses one definition plus every type it references (looked up below the same root), so each
:class:`~codegen.ir.CompositeType` resolves inside the returned Schema.

Without ``root``, ``parse_file`` walks up from the file: the root is the top-most ancestor named
``dsdl_specs`` or ``dsdl``; failing that, the top-most ancestor named ``dronecan``; in both cases
only if every directory between it and the file is a valid namespace component. Failing both,
the file's grandparent is the root, i.e. its directory is a one-component namespace. Pass
``root`` explicitly whenever the tree does not follow one of these conventions.

A service becomes two messages, ``dronecan.<full name>.Request`` and ``.Response`` (named
``<Short>Request`` / ``<Short>Response``), sharing the service's id and signature.
See dsdl_syntax (syntax), dsdl_signature (signatures, bit lengths) and dsdl_semantics
(docs, units, enums, sentinels).
"""

from __future__ import annotations

from pathlib import Path

from ...errors import SchemaError
from ...ir import (
    ArrayType,
    CastMode,
    CompositeType,
    Constant,
    DronecanInfo,
    DronecanKind,
    Field,
    FieldType,
    Location,
    Message,
    PrimitiveKind,
    PrimitiveType,
    Schema,
    SourceFormat,
)
from ...text.files import display_path, read_text
from . import semantics as sem
from .signature import data_type_signature, dsdl_signature, normalized_definition, section_max_bits, section_min_bits
from .syntax import (
    ArrayT,
    AttrT,
    PrimT,
    RefT,
    Section,
    TypeDef,
    VoidT,
    check_full_name,
    parse_source,
    split_file_name,
    valid_namespace_component,
)

PREFIX = "dronecan."
_ROOT_MARKERS = (("dsdl_specs", "dsdl"), ("dronecan",))


def parse_file(path: Path, *, root: Path | None = None) -> Schema:
    root = _find_root(path) if root is None else root
    loader = _Loader(root)
    loader.load_path(path)
    return loader.schema()


def parse_dir(root: Path) -> Schema:
    if not root.is_dir():
        raise SchemaError(root.as_posix(), 0, "expected a DSDL root directory")
    loader = _Loader(root)
    for path in sorted(root.rglob("*.uavcan")):
        if path.is_file():
            loader.load_path(path)
    loader.check_unique_ids()
    return loader.schema()


def _find_root(path: Path) -> Path:
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


# --------------------------------------------------------------------------------------------
# Loading: files, name lookup, references


class _Loader:
    def __init__(self, root: Path) -> None:
        self.root = root
        self._abs_root = root.resolve()
        self.defs: dict[str, TypeDef] = {}
        self._by_path: dict[Path, TypeDef] = {}
        self._loading: list[str] = []
        self._signatures: dict[str, int] = {}

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
        text = read_text(path, display)
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

    def lookup(self, full_name: str) -> TypeDef:
        return self.defs[full_name]

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

    def schema(self) -> Schema:
        messages: list[Message] = []
        for td in self.defs.values():
            messages.extend(self._messages(td))
        messages.sort(key=lambda m: m.qualified_name)
        sources = tuple(sorted(td.file for td in self.defs.values()))
        return Schema(messages=tuple(messages), sources=sources)

    # ----------------------------------------------------------------------------------------
    # IR assembly

    def _messages(self, td: TypeDef) -> list[Message]:
        signature = data_type_signature(td, self.lookup, self._signatures)
        normalized = normalized_definition(td)
        if td.response is None:
            halves = [(PREFIX + td.full_name, td.short_name, DronecanKind.MESSAGE, td.request)]
        else:
            base = PREFIX + td.full_name
            halves = [
                (f"{base}.Request", f"{td.short_name}Request", DronecanKind.REQUEST, td.request),
                (f"{base}.Response", f"{td.short_name}Response", DronecanKind.RESPONSE, td.response),
            ]
        out = []
        for qualified, name, kind, section in halves:
            info = DronecanInfo(
                full_name=td.full_name,
                data_type_id=td.default_id,
                signature=signature,
                kind=kind,
                union=section.union,
                min_bitlen=section_min_bits(section, self.lookup),
                max_bitlen=section_max_bits(section, self.lookup),
                min_bitlen_tao=section_min_bits(section, self.lookup),
                max_bitlen_tao=section_max_bits(section, self.lookup, tao=True),
                normalized_definition=normalized,
            )
            out.append(self._message(td, qualified, name, section, info))
        return out

    def _message(self, td: TypeDef, qualified: str, name: str, section: Section, info: DronecanInfo) -> Message:
        enums, links = sem.group_enums(qualified, section.constants, section.fields, td.file)
        invalid = sem.sentinels(section.constants, section.fields)
        fields = []
        for f in section.fields:
            unit_text, value_range, rest = sem.split_tag(f.trailing)
            is_float = isinstance(f.type, PrimT) and f.type.kind == "float"
            tagged, problem, rest = sem.split_invalid(rest, is_float)
            if problem:
                raise SchemaError(td.file, f.line, problem)
            fields.append(
                Field(
                    name=f.name if f.name and not isinstance(f.type, VoidT) else "",
                    type=_ir_type(f.type),
                    location=Location(td.file, f.line),
                    doc=sem.join_doc(f.above, rest),
                    unit=sem.resolve_unit(unit_text) if unit_text else None,
                    unit_text=unit_text,
                    range=value_range,
                    invalid=invalid.get(f.name or "") or tagged,
                    enums=links.get(f.name or "", ()),
                )
            )
        constants = tuple(
            Constant(
                c.name, _ir_primitive(c.type), c.value, sem.join_doc(c.above, c.trailing), Location(td.file, c.line)
            )
            for c in section.constants
        )
        return Message(
            name=name,
            qualified_name=qualified,
            format=SourceFormat.DRONECAN,
            location=Location(td.file, section.line),
            doc=td.doc,
            fields=tuple(fields),
            constants=constants,
            enums=enums,
            dronecan=info,
        )


_KINDS = {
    "bool": PrimitiveKind.BOOL,
    "uint": PrimitiveKind.UINT,
    "int": PrimitiveKind.INT,
    "float": PrimitiveKind.FLOAT,
}


def _ir_primitive(t: PrimT) -> PrimitiveType:
    return PrimitiveType(_KINDS[t.kind], t.bits, CastMode(t.cast))


def _ir_type(t: AttrT) -> FieldType:
    if isinstance(t, PrimT):
        return _ir_primitive(t)
    if isinstance(t, VoidT):
        return PrimitiveType(PrimitiveKind.VOID, t.bits)
    if isinstance(t, RefT):
        return CompositeType(PREFIX + t.full_name)
    element = _ir_type(t.element)
    return ArrayType(element, t.size, t.dynamic, 0 if t.dynamic else t.size)

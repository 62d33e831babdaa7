"""The live tree a .dts builds: merging blocks, deletions, references and phandles as dtc does.

dtc semantics kept here: a later block for the same node merges into it (a property redefined
keeps its place, new ones are appended); /delete-node/ and /delete-property/ act on what earlier
blocks defined; a ``<&label>`` gives the target a phandle, numbered from 1 in document order
skipping explicit ones, and a ``phandle`` property appended to the target; ``&label`` outside
cells becomes the target's path string.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

from .model import DevicetreeError, DtNode, DtPart, DtValue


@dataclass
class Ref:
    """A reference to a node: ``&label``, ``&{/path}`` or ``&{label/sub/path}``."""

    text: str
    file: str
    line: int


@dataclass
class Draft:
    """One piece of a value before references are resolved (see DtPart for the kinds)."""

    kind: str
    items: list[int | Ref] | str | bytes | Ref
    bits: int = 32


@dataclass
class Prop:
    name: str
    value: list[Draft]
    file: str
    line: int
    deleted: bool = False  # a /delete-property/ marker while in a block not yet merged


@dataclass
class Node:
    name: str
    file: str
    line: int
    labels: list[str] = field(default_factory=list)
    props: list[Prop] = field(default_factory=list)
    children: list[Node] = field(default_factory=list)
    deleted: bool = False  # a /delete-node/ marker while in a block not yet merged
    omit_if_no_ref: bool = False
    referenced: bool = False
    phandle: int | None = None
    parent: Node | None = None

    def live_children(self) -> Iterator[Node]:
        return (c for c in self.children if not c.deleted)

    def live_props(self) -> Iterator[Prop]:
        return (p for p in self.props if not p.deleted)

    def path(self) -> str:
        if self.parent is None:
            return "/"
        base = self.parent.path()
        return f"{'' if base == '/' else base}/{self.name}"

    def walk(self) -> Iterator[Node]:
        yield self
        for child in self.live_children():
            yield from child.walk()


def attach(parent: Node, child: Node) -> None:
    child.parent = parent
    parent.children.append(child)


def delete(node: Node) -> None:
    """dtc's delete_node: the node stays as a tombstone (a later block of that name revives it in
    place), with its properties, children and labels deleted."""
    node.deleted = True
    node.labels.clear()
    for prop in node.props:
        prop.deleted = True
    for child in node.children:
        delete(child)


def merge(old: Node, new: Node) -> None:
    """Merge a later block ``new`` into ``old`` as dtc's merge_nodes does; ``new``'s deleted
    entries are /delete-*/ markers, ``old``'s are tombstones."""
    old.deleted = False
    for label in new.labels:
        if label not in old.labels:
            old.labels.append(label)
    old.omit_if_no_ref = old.omit_if_no_ref or new.omit_if_no_ref
    for prop in new.props:
        index = next((i for i, p in enumerate(old.props) if p.name == prop.name), None)
        if prop.deleted:
            if index is not None:
                old.props[index].deleted = True
        elif index is not None:
            old.props[index] = prop
        else:
            old.props.append(prop)
    for child in new.children:
        if child.deleted:
            live = next((c for c in old.live_children() if c.name == child.name), None)
            if live is not None:
                delete(live)
            continue
        same = next((c for c in old.children if c.name == child.name), None)
        if same is not None:
            merge(same, child)
        else:
            attach(old, child)


def find(root: Node, ref: Ref) -> Node | None:
    """The node a reference names, or None."""
    text = ref.text
    if text.startswith("/"):
        node: Node | None = root
        for part in (p for p in text.split("/") if p):
            node = next((c for c in node.live_children() if c.name == part), None) if node else None
        return node
    label, _, rest = text.partition("/")
    start = next((n for n in root.walk() if label in n.labels), None)
    if start is None or not rest:
        return start
    return find_below(start, rest)


def find_below(start: Node, rest: str) -> Node | None:
    node: Node | None = start
    for part in (p for p in rest.split("/") if p):
        node = next((c for c in node.live_children() if c.name == part), None) if node else None
    return node


def _refs(root: Node) -> Iterator[tuple[Node, Prop, Ref]]:
    for node in root.walk():
        for prop in node.live_props():
            for draft in prop.value:
                items = draft.items
                if isinstance(items, Ref):
                    yield node, prop, items
                elif isinstance(items, list):
                    for item in items:
                        if isinstance(item, Ref):
                            yield node, prop, item


def _target(root: Node, ref: Ref) -> Node:
    node = find(root, ref)
    if node is None:
        raise DevicetreeError(
            ref.file, ref.line, f"reference &{_show(ref)} names no node: expected a defined label or path"
        )
    return node


def _show(ref: Ref) -> str:
    return ref.text if ref.text[:1].isalpha() or ref.text[:1] == "_" else "{" + ref.text + "}"


def _cells_of(prop: Prop) -> list[int] | None:
    if len(prop.value) == 1 and prop.value[0].kind == "cells" and prop.value[0].bits == 32:
        items = prop.value[0].items
        if isinstance(items, list) and all(isinstance(i, int) for i in items):
            return [i for i in items if isinstance(i, int)]
    return None


def finish(root: Node) -> list[DtNode]:
    """Resolve references, drop unreferenced /omit-if-no-ref/ nodes, assign phandles, check dtc's
    errors (duplicate names and labels) and flatten to DtNodes in document order."""
    for _, _, ref in _refs(root):
        _target(root, ref).referenced = True
    for node in list(root.walk()):
        if node.omit_if_no_ref and not node.referenced and node.parent is not None:
            delete(node)
    _check_duplicates(root)
    used: set[int] = set()
    for node in root.walk():
        for prop in node.live_props():
            if prop.name in ("phandle", "linux,phandle"):
                cells = _cells_of(prop)
                if cells is None or len(cells) != 1 or cells[0] in (0, 0xFFFFFFFF):
                    raise DevicetreeError(
                        prop.file, prop.line, f"{prop.name}: expected one cell other than 0 and 0xffffffff"
                    )
                if node.phandle is not None and node.phandle != cells[0]:
                    raise DevicetreeError(prop.file, prop.line, "phandle and linux,phandle disagree")
                if node.phandle is None and cells[0] in used:
                    raise DevicetreeError(
                        prop.file, prop.line, f"phandle {cells[0]:#x} is already used by another node"
                    )
                node.phandle = cells[0]
                used.add(cells[0])
    counter = 1
    for _, prop, ref in _refs(root):
        target = _target(root, ref)
        if target.phandle is not None or not _in_cells(prop, ref):
            continue
        while counter in used:
            counter += 1
        target.phandle = counter
        used.add(counter)
        target.props.append(Prop("phandle", [Draft("cells", [counter])], target.file, target.line))
    return [_flatten(root, node) for node in root.walk()]


def _in_cells(prop: Prop, ref: Ref) -> bool:
    return any(isinstance(d.items, list) and any(i is ref for i in d.items) for d in prop.value)


def _check_duplicates(root: Node) -> None:
    seen_labels: dict[str, Node] = {}
    for node in root.walk():
        names: set[str] = set()
        for prop in node.live_props():
            if prop.name in names:
                raise DevicetreeError(prop.file, prop.line, f"duplicate property {prop.name!r} in {node.path()}")
            names.add(prop.name)
        children: set[str] = set()
        for child in node.children:  # dtc counts /delete-node/ markers of the same block too
            if child.name in children:
                raise DevicetreeError(child.file, child.line, f"duplicate node name {child.name!r} in {node.path()}")
            children.add(child.name)
        for label in node.labels:
            other = seen_labels.setdefault(label, node)
            if other is not node:
                raise DevicetreeError(
                    node.file, node.line, f"duplicate label {label!r} on {other.path()} and {node.path()}"
                )


def _flatten(root: Node, node: Node) -> DtNode:
    props: dict[str, DtValue] = {}
    for prop in node.live_props():
        data = bytearray()
        parts: list[DtPart] = []
        for draft in prop.value:
            chunk, part = _encode(root, draft)
            data += chunk
            parts.append(part)
        props[prop.name] = DtValue(bytes(data), tuple(parts), prop.line, prop.file)
    return DtNode(node.path(), props, tuple(node.labels), node.line, node.file)


def _encode(root: Node, draft: Draft) -> tuple[bytes, DtPart]:
    items = draft.items
    if draft.kind == "string":
        assert isinstance(items, str)
        return items.encode("utf-8", "surrogateescape") + b"\0", DtPart("string", items)
    if draft.kind == "bytes":
        assert isinstance(items, bytes)
        return items, DtPart("bytes", items)
    if draft.kind == "path":
        assert isinstance(items, Ref)
        path = _target(root, items).path()
        return path.encode() + b"\0", DtPart("path", path)
    assert isinstance(items, list)
    values: list[int] = []
    for item in items:
        if isinstance(item, Ref):
            phandle = _target(root, item).phandle
            assert phandle is not None
            values.append(phandle)
        else:
            values.append(item)
    size = draft.bits // 8
    data = b"".join(v.to_bytes(size, "big") for v in values)
    return data, DtPart("cells", tuple(values), draft.bits)

"""The <parameters> groups of an apm.pdef.xml file -> one IR Message each.

A group ``<parameters name="BATT_">`` becomes Message ``params.BATT`` (trailing ``_`` dropped),
its <param>s the fields. Under <libraries> a group's name is the prefix of its parameters
(``BATT_`` + ``LOW_VOLT``); under <vehicles> it is the vehicle and the parameters have no prefix.
"""

from __future__ import annotations

import re

from ...ir import Constant, EnumDef, Field, Message, PdefInfo, SourceFormat
from .parameter import parameter
from .tree import Element

PREFIX = "params."  # qualified names of parameter groups: the IR's name of the format
_GROUP_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")


def group_messages(doc: Element) -> list[Message]:
    """Every group of a file, from its root element, in document order."""
    if doc.tag != "paramfile":
        raise doc.error(f"expected <paramfile> as the root element, got <{doc.tag}>")
    out: list[Message] = []
    names: dict[str, int] = {}
    for section in doc.children:
        if section.tag not in ("vehicles", "libraries"):
            raise section.error(f"expected <vehicles> or <libraries> in <paramfile>, got <{section.tag}>")
        for group in section.children:
            if group.tag != "parameters":
                raise group.error(f"expected <parameters> in <{section.tag}>, got <{group.tag}>")
            msg = _group(group, section.tag)
            if msg.name in names:
                raise group.error(f"expected one <parameters name=...> group {msg.name} (also line {names[msg.name]})")
            names[msg.name] = group.line
            out.append(msg)
    return out


def _group(node: Element, section: str) -> Message:
    raw = node.attrs.get("name")
    if raw is None:
        raise node.error('expected a "name" attribute on <parameters>')
    name = raw.rstrip("_")
    if not _GROUP_NAME.fullmatch(name):
        raise node.error(f"expected a parameter group name (letters, digits, _), got {raw!r}")
    prefix = name + "_" if section == "libraries" else ""
    qualified = PREFIX + name
    fields: list[Field] = []
    constants: list[Constant] = []
    enums: list[EnumDef] = []
    seen: dict[str, int] = {}
    for child in node.children:
        if child.tag != "param":
            raise child.error(f"expected <param> in <parameters>, got <{child.tag}>")
        f, enum, members = parameter(child, qualified, prefix)
        if f.name in seen:
            raise child.error(f"expected each parameter once in group {name}: {f.name} is also at line {seen[f.name]}")
        seen[f.name] = child.line
        fields.append(f)
        if enum is not None:
            enums.append(enum)
            constants.extend(members)
    return Message(
        name=name,
        qualified_name=qualified,
        format=SourceFormat.PDEF,
        location=node.location(),
        doc=node.attrs.get("documentation", "").strip(),
        fields=tuple(fields),
        constants=tuple(constants),
        enums=tuple(enums),
        params=PdefInfo(prefix=prefix, section=section),
    )

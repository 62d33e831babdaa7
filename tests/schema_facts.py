"""What a tool reads from a schema, without the words: for comparing our bundled schemas with upstream's files.

The bundled schemas carry upstream's facts (names, types, order, ids, units, ranges, invalid markers, enums,
constants, layouts) in our own words. :func:`facts` turns an IR value into something comparable with the prose
and the source positions taken out; :func:`prose` lists the descriptions and comments of a schema file, so a
test can check that none of them is upstream's text.
"""

from __future__ import annotations

import dataclasses
import re
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import yaml

_WORDS = ("doc",)  # IR attributes that hold prose
_PLACES = ("location",)  # IR attributes that hold a source position
_CHOICE_NOTE = "choice."  # devicetree annotation holding a choice's description


def facts(value: Any) -> str:
    """``value`` (a Message, Field, ...) with every doc emptied and every location dropped, as a repr:
    two schemas with the same facts give the same text (NaN compares equal, as its repr does)."""
    return repr(_strip(value))


def _strip(value: Any) -> Any:
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        changes: dict[str, Any] = {}
        for f in dataclasses.fields(value):
            if f.name in _WORDS:
                changes[f.name] = ""
            elif f.name in _PLACES:
                changes[f.name] = None
            elif f.name == "annotations":
                changes[f.name] = tuple((k, "" if k.startswith(_CHOICE_NOTE) else v) for k, v in value.annotations)
            else:
                changes[f.name] = _strip(getattr(value, f.name))
        return dataclasses.replace(value, **changes)
    if isinstance(value, tuple):
        return tuple(_strip(v) for v in value)
    return value


def _fold(text: str) -> str:
    return " ".join(text.split())


_TAGS = re.compile(r"^(?:\s*\[[^\]]*\])*")  # leading [unit] / [@tag ...] metadata of a comment


def prose(path: Path) -> list[str]:
    """The descriptions and comments of a schema file, whitespace folded: a '#' comment's text (its leading
    bracketed metadata left out) for .msg/.uavcan/.dsdl, description and field texts for MAVLink XML, every
    ``description`` value and comment for a dt-schema YAML."""
    text = path.read_text(encoding="utf-8")
    if path.suffix == ".xml":
        root = ET.fromstring(text)
        texts = [e.text or "" for e in root.iter() if e.tag in ("description", "field")]
        return [_fold(text) for text in texts if text.strip()]
    out = [_fold(_TAGS.sub("", line.split("#", 1)[1])) for line in text.splitlines() if "#" in line]
    if path.suffix == ".yaml":
        out = [c for c in out if not c.startswith(("/", "'"))]  # '#' inside $ref values and patterns
        out += [_fold(d) for d in _descriptions(yaml.safe_load(text))]
    return [p for p in out if p]


def _descriptions(node: Any) -> list[str]:
    if isinstance(node, dict):
        found = [v for k, v in node.items() if k == "description" and isinstance(v, str)]
        return found + [d for k, v in node.items() if k != "description" for d in _descriptions(v)]
    if isinstance(node, list):
        return [d for v in node for d in _descriptions(v)]
    return []


def shared_lines(ours: Path, upstream: list[Path], *, shortest: int = 30) -> list[str]:
    """Our descriptions and comments of at least ``shortest`` characters that upstream has word for word, as a
    whole description, a whole comment or one line of its file (whitespace folded)."""
    theirs: set[str] = set()
    for path in upstream:
        theirs.update(prose(path))
        for line in path.read_text(encoding="utf-8").splitlines():
            theirs.add(_fold(line))
            theirs.add(_fold(re.sub(r"^\s*(#|//|\*|-)\s*|^\s*description:\s*\|?", "", line)))
            theirs.add(_fold(_TAGS.sub("", line.split("#", 1)[1])) if "#" in line else "")
    pieces = {p for text in prose(ours) for p in (text, *text.split(". "))}
    return sorted(p for p in pieces if len(p) >= shortest and (p in theirs or p.rstrip(".") in theirs))

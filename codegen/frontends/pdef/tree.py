"""An apm.pdef.xml file as a small element tree whose elements know their file and line.

Read with the shared hardened expat set-up (codegen.text.xml: UTF-8, no DTDs, no entities);
the files are small, and a tree lets a <param> look at all its <field>s before deciding its type.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from ...errors import SchemaError
from ...ir import Location
from ...text.xml import XmlReader, read_xml


@dataclass
class Element:
    tag: str
    attrs: dict[str, str]
    file: str  # the display path, for errors and IR locations
    line: int
    children: list[Element] = field(default_factory=list)
    text: str = ""  # stripped character data directly inside the element

    def error(self, message: str) -> SchemaError:
        return SchemaError(self.file, self.line, message)

    def location(self) -> Location:
        return Location(self.file, self.line)


class _TreeBuilder(XmlReader):
    def __init__(self, display: str) -> None:
        super().__init__(display, no_dtd_because="apm.pdef.xml needs no DTD")
        self.stack: list[Element] = []
        self.chunks: list[list[str]] = []  # the text pieces of each open element, joined once it closes
        self.root: Element | None = None

    def start(self, tag: str, attrs: dict[str, str]) -> None:
        node = Element(tag, dict(attrs), self.display, self.line)
        if self.stack:
            self.stack[-1].children.append(node)
        else:
            self.root = node
        self.stack.append(node)
        self.chunks.append([])

    def end(self, tag: str) -> None:
        node = self.stack.pop()
        node.text = "".join(self.chunks.pop()).strip()  # one join: appending piece by piece is quadratic

    def text(self, data: str) -> None:
        if self.chunks:
            self.chunks[-1].append(data)


def read_tree(path: Path, display: str) -> Element:
    """The root element of one file; SchemaError (file, line) when it is unreadable or not well-formed."""
    builder = _TreeBuilder(display)
    builder.read(read_xml(path, display))
    assert builder.root is not None  # expat rejects an empty document
    return builder.root

"""The one XML parser set-up of the schema frontends (MAVLink dialects, ArduPilot parameter metadata).

Every XML file battgen reads goes through :class:`XmlReader`, an expat parser with these protections:

- The file must be UTF-8 text (:func:`read_xml`, errors at the offending line); expat gets exactly
  those bytes, so what is checked is what a later parser (pymavlink) reads.
- No DOCTYPE at all: an internal subset could declare entity expansion bombs, an external DTD
  would make the parser read other files or the network. Parameter entities are never parsed and
  ENTITY declarations are refused in their own right, should one ever reach a handler.
- Errors are :class:`~codegen.errors.SchemaError` at a file and line: ``expected well-formed XML
  (<expat's message>)`` for malformed documents, and whatever a format's handlers raise.

Expat streams the document, so a format reads it in document order by overriding
:meth:`XmlReader.start`, :meth:`XmlReader.end` and :meth:`XmlReader.text`; :attr:`XmlReader.line` is
the line being read and :meth:`XmlReader.error` makes a SchemaError there. Each format keeps its own
limits (field counts, id ranges...), which belong to the format rather than to XML.
"""

from __future__ import annotations

import xml.parsers.expat
from pathlib import Path

from ..errors import SchemaError
from .files import read_text


def read_xml(path: Path, display: str) -> bytes:
    """The bytes of an XML file, once they are known to be UTF-8 text (SchemaError otherwise)."""
    return read_text(path, display).encode("utf-8")


class XmlReader:
    """An expat parser that refuses DTDs and entities; subclasses receive the elements.

    ``no_dtd_because`` completes the refusal of a DOCTYPE: ``expected no DOCTYPE (<no_dtd_because>)``.
    """

    def __init__(self, display: str, *, no_dtd_because: str) -> None:
        self.display = display
        self._no_dtd_because = no_dtd_because
        self._parser = xml.parsers.expat.ParserCreate()
        p = self._parser
        p.SetParamEntityParsing(xml.parsers.expat.XML_PARAM_ENTITY_PARSING_NEVER)
        p.StartDoctypeDeclHandler = self._doctype
        p.EntityDeclHandler = self._entity
        p.StartElementHandler = self.start
        p.EndElementHandler = self.end
        p.CharacterDataHandler = self.text

    @property
    def line(self) -> int:
        """The line expat is at: where the element being started or ended is written."""
        return self._parser.CurrentLineNumber

    def error(self, message: str) -> SchemaError:
        return SchemaError(self.display, self.line, message)

    def start(self, tag: str, attrs: dict[str, str]) -> None:
        """An element opens (attributes in a plain dict)."""

    def end(self, tag: str) -> None:
        """An element closes."""

    def text(self, data: str) -> None:
        """Character data, possibly in several pieces for one run of text."""

    def read(self, data: bytes) -> None:
        """Parse one whole document, calling the handlers; SchemaError when it is not well-formed."""
        try:
            self._parser.Parse(data, True)
        except xml.parsers.expat.ExpatError as exc:
            message = xml.parsers.expat.errors.messages.get(exc.code, str(exc))
            raise SchemaError(self.display, exc.lineno, f"expected well-formed XML ({message})") from None

    def _doctype(self, *_: object) -> None:
        raise self.error(f"expected no DOCTYPE ({self._no_dtd_because})")

    def _entity(self, *_: object) -> None:
        raise self.error("expected no ENTITY declarations")

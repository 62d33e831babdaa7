"""The one XML parser set-up of the schema frontends (MAVLink dialects, ArduPilot parameter metadata).

Every XML file battgen reads goes through :class:`XmlReader`, an expat parser with these protections:

- The file must be UTF-8 text (:func:`read_xml`, errors at the offending line); expat gets exactly
  those bytes, so what is checked is what a later parser (pymavlink) reads.
- No DOCTYPE at all: an internal subset could declare entity expansion bombs, an external DTD
  would make the parser read other files or the network. Parameter entities are never parsed and
  ENTITY declarations are refused in their own right, should one ever reach a handler.
- Errors are :class:`~codegen.errors.SchemaError` at a file and line: ``expected well-formed XML
  (<expat's message>)`` for malformed documents, and whatever a format's handlers raise.

- The limits of :mod:`.limits`, checked while expat streams (before any later parser sees the
  bytes): the file's size and number lengths, an encoding declared as UTF-8 if declared at all, the
  nesting depth and the length of one element's text.

Expat streams the document, so a format reads it in document order by overriding
:meth:`XmlReader.start`, :meth:`XmlReader.end` and :meth:`XmlReader.text`; :attr:`XmlReader.line` is
the line being read and :meth:`XmlReader.error` makes a SchemaError there. Each format keeps its own
limits (field counts, id ranges...), which belong to the format rather than to XML.
"""

from __future__ import annotations

import re
import xml.parsers.expat
from pathlib import Path

from ..errors import SchemaError
from .limits import MAX_XML_DEPTH, MAX_XML_TEXT, read_schema_text

# the encoding named by an XML declaration; expat (and pymavlink after it) would look any name up
_DECLARED_ENCODING = re.compile(r"""\ufeff?<\?xml[^>]*?\bencoding\s*=\s*["']([^"']*)["']""")


def read_xml(path: Path, display: str) -> bytes:
    """The bytes of an XML file, once they are known to be UTF-8 text within the schema limits and
    declare no other encoding (SchemaError otherwise)."""
    text = read_schema_text(path, display)
    match = _DECLARED_ENCODING.match(text)
    if match is not None and match.group(1).lower().replace("_", "-") not in ("utf-8", "utf8"):
        raise SchemaError(
            display,
            1,
            f'expected encoding="UTF-8" in the XML declaration (schema files are UTF-8), got {match.group(1)[:40]!r}',
        )
    return text.encode("utf-8")


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
        p.StartElementHandler = self._start
        p.EndElementHandler = self._end
        p.CharacterDataHandler = self._text
        self._depth = 0
        self._text_length = 0  # characters of text since the last tag

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

    def _start(self, tag: str, attrs: dict[str, str]) -> None:
        self._depth += 1
        self._text_length = 0
        if self._depth > MAX_XML_DEPTH:
            raise self.error(f"expected elements nested at most {MAX_XML_DEPTH} deep (docs/limits.md)")
        self.start(tag, attrs)

    def _end(self, tag: str) -> None:
        self._depth -= 1
        self._text_length = 0
        self.end(tag)

    def _text(self, data: str) -> None:
        self._text_length += len(data)
        if self._text_length > MAX_XML_TEXT:
            raise self.error(f"expected at most {MAX_XML_TEXT} characters of text in one element (docs/limits.md)")
        self.text(data)

    def _doctype(self, *_: object) -> None:
        raise self.error(f"expected no DOCTYPE ({self._no_dtd_because})")

    def _entity(self, *_: object) -> None:
        raise self.error("expected no ENTITY declarations")

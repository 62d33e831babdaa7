"""Character-level scanning of devicetree source: positions, comments, /include/, cpp line markers.

The parser reads characters directly (dtc's lexer is modal too: names, cells and byte strings
tokenise differently), so this module only moves over what separates tokens and knows where
each character came from.
"""

from __future__ import annotations

import bisect
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

from ...errors import SchemaError
from ...text.files import display_path, read_text
from .model import DevicetreeError

CPP_HINT = "run the C preprocessor first (cpp -nostdinc -undef -x assembler-with-cpp)"
_CPP_DIRECTIVES = frozenset("include define undef if ifdef ifndef elif else endif error warning pragma".split())
_LINEMARKER = re.compile(r'#(?:line)?[ \t]+([0-9]+)[ \t]+"((?:[^"\\\n]|\\.)*)"[^\n]*')
_DIRECTIVE = re.compile(r"#[ \t]*([a-z]+)(?=[\s<\"]|$)")
_WS = " \t\r\n\f\v"
_WORD = re.compile(r"[A-Za-z0-9_,.+*#?@-]+|\S")
MAX_INCLUDE_DEPTH = 100


@dataclass
class Source:
    """One file being read: its text, where we are, and cpp line markers seen so far."""

    text: str
    display: str
    path: Path | None
    pos: int = 0
    line_starts: list[int] = field(default_factory=list)
    markers: list[tuple[int, str, int]] = field(default_factory=list)  # (physical line, file, line)

    def __post_init__(self) -> None:
        self.line_starts = [0] + [m.end() for m in re.finditer("\n", self.text)]

    def where(self, pos: int) -> tuple[str, int]:
        """(file, 1-based line) of a character, honouring ``# 12 "file"`` markers."""
        phys = bisect.bisect_right(self.line_starts, pos)
        i = bisect.bisect_right(self.markers, (phys, "\uffff", 0)) - 1
        if i < 0:
            return self.display, phys
        start, file, line = self.markers[i]
        return file, line + phys - start


class Scanner:
    """A stack of sources (the file and what it /include/s) read as one stream."""

    def __init__(self, path: Path, display: str, root: Path | None = None) -> None:
        self.stack = [Source(_read(path, display), display, path.resolve())]
        self.root = root
        # /include/ and /incbin/ reach only below the top file's folder and the BATTGEN_DTS_PATH folders:
        # a board file must not read /etc/passwd or /dev/zero into a property
        extra = [Path(p).resolve() for p in os.environ.get("BATTGEN_DTS_PATH", "").split(os.pathsep) if p]
        self.folders = [path.resolve().parent, *extra]

    def allowed(self, target: Path) -> bool:
        """Whether an /include/ or /incbin/ target (resolved) lies below an allowed folder."""
        return any(target.is_relative_to(folder) for folder in self.folders)

    def allowed_text(self) -> str:
        return "add its folder to BATTGEN_DTS_PATH to allow it"

    @property
    def src(self) -> Source:
        return self.stack[-1]

    def where(self) -> tuple[str, int]:
        return self.src.where(self.src.pos)

    def error(self, message: str, at: tuple[str, int] | None = None) -> DevicetreeError:
        file, line = at or self.where()
        return DevicetreeError(file, line, message)

    # -- moving over the gaps between tokens ------------------------------------------------

    def skip(self) -> None:
        """Skip blanks, comments, line markers and /include/ (entering the file); pop finished files."""
        while True:
            src = self.src
            text, n = src.text, len(src.text)
            pos = src.pos
            while pos < n:
                c = text[pos]
                if c in _WS:
                    pos += 1
                elif text.startswith("/*", pos):
                    end = text.find("*/", pos + 2)
                    if end < 0:
                        src.pos = pos
                        raise self.error("unterminated comment: expected */")
                    pos = end + 2
                elif text.startswith("//", pos):
                    end = text.find("\n", pos)
                    pos = n if end < 0 else end
                elif c == "#" and self._at_line_start(pos):
                    src.pos = pos
                    after = self._hash_line(pos)
                    if after is None:
                        break  # a property name such as #address-cells
                    pos = after
                else:
                    break
            src.pos = pos
            if pos < n and text.startswith("/include/", pos):
                self._include()
                continue
            if pos >= n and len(self.stack) > 1:
                self.stack.pop()
                continue
            return

    def _at_line_start(self, pos: int) -> bool:
        start = self.src.text.rfind("\n", 0, pos) + 1
        return self.src.text[start:pos].strip(" \t") == ""

    def _hash_line(self, pos: int) -> int | None:
        """A '#' at the start of a line: a cpp line marker (followed), a directive (refused) or a
        property name such as #address-cells (left for the parser)."""
        text = self.src.text
        marker = _LINEMARKER.match(text, pos)
        if marker:
            phys = bisect.bisect_right(self.src.line_starts, pos) + 1
            name = _unescape_marker(marker.group(2))
            if self.root is not None and Path(name).is_absolute():
                name = display_path(Path(name), self.root)  # keep locations checkout-independent
            self.src.markers.append((phys, name, int(marker.group(1))))
            return marker.end()
        directive = _DIRECTIVE.match(text, pos)
        if directive and directive.group(1) in _CPP_DIRECTIVES:
            raise self.error(f"C preprocessor directive #{directive.group(1)} is not devicetree syntax: {CPP_HINT}")
        return None

    def _include(self) -> None:
        at = self.where()
        self.src.pos += len("/include/")
        self.skip_blanks_only()
        if not self.peek('"'):
            raise self.error("expected a quoted file name after /include/")
        name = self.read_string()
        base = self.src.path.parent if self.src.path else Path.cwd()
        target = (base / name).resolve()
        display = os.path.normpath(os.path.join(os.path.dirname(self.src.display), name)).replace(os.sep, "/")
        chain = [s.path for s in self.stack]
        if not self.allowed(target):
            raise self.error(
                f'/include/ "{name}": outside the folder of {self.stack[0].display} ({self.allowed_text()})', at
            )
        if target in chain:
            cycle = " -> ".join([*(s.display for s in self.stack), display])
            raise self.error(f"/include/ cycle: {cycle}", at)
        if len(self.stack) >= MAX_INCLUDE_DEPTH:
            raise self.error(f"/include/ nested more than {MAX_INCLUDE_DEPTH} deep", at)
        if not target.is_file():
            raise self.error(f'/include/ "{name}": no such file (looked in {base.as_posix()})', at)
        self.stack.append(Source(_read(target, display), display, target))

    def skip_blanks_only(self) -> None:
        src = self.src
        while src.pos < len(src.text) and src.text[src.pos] in _WS:
            src.pos += 1

    # -- looking at and taking characters ---------------------------------------------------

    def ws(self) -> None:
        self.skip()

    def peek(self, s: str) -> bool:
        return self.src.text.startswith(s, self.src.pos)

    def at(self, s: str) -> bool:
        self.ws()
        return self.peek(s)

    def char(self) -> str:
        src = self.src
        return src.text[src.pos] if src.pos < len(src.text) else ""

    def eof(self) -> bool:
        self.ws()
        return self.src.pos >= len(self.src.text) and len(self.stack) == 1

    def take(self, s: str) -> bool:
        if self.at(s):
            self.src.pos += len(s)
            return True
        return False

    def expect(self, s: str, what: str) -> None:
        if not self.take(s):
            raise self.error(f"expected {what}, found {self.describe()}")

    def describe(self) -> str:
        """The upcoming text, for error messages."""
        self.ws()
        src = self.src
        if src.pos >= len(src.text):
            return "end of file"
        word = _WORD.match(src.text, src.pos)
        if not word:  # a character no token starts with (a no-break space pasted from a web page, say)
            return f"the character {src.text[src.pos]!r}"
        text = word.group(0)  # quoted briefly: a "word" of hostile input can be megabytes long
        return repr(text) if len(text) <= 60 else repr(text[:57]) + "..."

    def match(self, pattern: re.Pattern[str]) -> str | None:
        m = pattern.match(self.src.text, self.src.pos)
        if not m:
            return None
        self.src.pos = m.end()
        return m.group(0)

    # -- strings and character literals -------------------------------------------------------

    def read_string(self) -> str:
        """A double-quoted string (at the cursor) with C escapes; returns the decoded text."""
        at = self.where()
        src = self.src
        text = src.text
        pos = src.pos + 1
        out: list[str] = []
        while True:
            if pos >= len(text):
                raise self.error('unterminated string: expected a closing "', at)
            c = text[pos]
            if c == '"':
                src.pos = pos + 1
                return "".join(out)
            if c == "\\":
                ch, pos = unescape(text, pos + 1)
                out.append(ch)
            else:
                out.append(c)
                pos += 1

    def read_char_literal(self) -> int:
        at = self.where()
        text = self.src.text
        pos = self.src.pos + 1
        chars: list[str] = []
        while pos < len(text) and text[pos] not in "'\n":
            if text[pos] == "\\":
                ch, pos = unescape(text, pos + 1)
            else:
                ch, pos = text[pos], pos + 1
            chars.append(ch)
        if pos >= len(text) or text[pos] != "'":
            raise self.error("unterminated character literal: expected a closing '", at)
        self.src.pos = pos + 1
        data = "".join(chars).encode("utf-8", "surrogateescape") if chars else b""
        if len(chars) != 1 or len(data) != 1:
            raise self.error(f"character literal holds {len(data)} bytes: expected exactly one", at)
        return data[0]


def _read(path: Path, display: str) -> str:
    try:
        return read_text(path, display, what="a devicetree source")
    except SchemaError as exc:
        raise DevicetreeError(exc.file, exc.line, exc.message) from None


_SIMPLE_ESCAPES = {"a": "\a", "b": "\b", "t": "\t", "n": "\n", "v": "\v", "f": "\f", "r": "\r"}


def unescape(text: str, pos: int) -> tuple[str, int]:
    """Decode the escape after a backslash at ``pos - 1``; octal/hex give raw bytes (as surrogates
    for values above 0x7f, so encoding with surrogateescape restores the byte)."""
    if pos >= len(text):
        return "\\", pos
    c = text[pos]
    if c in _SIMPLE_ESCAPES:
        return _SIMPLE_ESCAPES[c], pos + 1
    oct_m = re.match(r"[0-7]{1,3}", text[pos : pos + 3])
    if oct_m:
        return _byte(int(oct_m.group(0), 8) & 0xFF), pos + len(oct_m.group(0))
    if c == "x":
        hex_m = re.match(r"[0-9a-fA-F]{1,2}", text[pos + 1 : pos + 3])
        if hex_m:
            return _byte(int(hex_m.group(0), 16)), pos + 1 + len(hex_m.group(0))
    return c, pos + 1


def _byte(value: int) -> str:
    return chr(value) if value < 0x80 else chr(0xDC00 + value)


def _unescape_marker(name: str) -> str:
    return re.sub(r"\\(.)", r"\1", name)

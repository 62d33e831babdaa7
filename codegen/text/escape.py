"""Text from an input made safe to print: the one output boundary of battgen.

Anything a log, capture, file name or schema holds may reach a terminal or a CI log: a topic named
``"x\\n::error file=X,line=1::..."`` would start a GitHub workflow command on a line of its own, an
``ESC ]0;...BEL`` would retitle the terminal, a cell ``=HYPERLINK(...)`` becomes a formula in a
spreadsheet. Every place that prints such text passes it through one of these functions:

- :func:`shown`: control characters (C0, DEL, C1) as ``\\xNN``, and the Unicode line separators and
  bidirectional controls (which reorder or break what a reader sees) as ``\\uNNNN``;
- :func:`line`: one printed line -- :func:`shown`, and a line that would start a GitHub workflow
  command (``::``, after blanks, as the runner trims them) or hold the runner's legacy ``##[`` prefix
  gets its colon or hash written as ``\\x3a`` / ``\\x23``;
- :func:`github_data` / :func:`github_property`: the Actions runner's own escaping of a workflow
  command's message and properties (``%25 %0D %0A``, properties also ``%3A %2C``), other controls as
  :func:`shown`;
- :func:`csv_cell`: a text cell guarded as OWASP's "CSV Injection" page describes: one beginning with
  ``= + - @``, tab or CR gets a leading single quote.
"""

from __future__ import annotations

import re

# C0 but for nothing, DEL, C1: shown as \xNN
_CONTROL = "".join(chr(c) for c in (*range(0x20), *range(0x7F, 0xA0)))
# line and paragraph separators, bidi embeddings/overrides/isolates and marks: shown as \uNNNN
_INVISIBLE = "\u2028\u2029\u200e\u200f\u202a\u202b\u202c\u202d\u202e\u2066\u2067\u2068\u2069\u061c"
_UNSAFE = re.compile(f"[{re.escape(_CONTROL + _INVISIBLE)}]")
_UNSAFE_KEEP_LINES = re.compile(f"[{re.escape(_CONTROL.replace(chr(13), '').replace(chr(10), '') + _INVISIBLE)}]")
_COMMAND_START = re.compile(r"^(\s*):")  # the runner trims leading blanks before looking for '::'
CSV_TRIGGERS = ("=", "+", "-", "@", "\t", "\r")


def _code(match: re.Match[str]) -> str:
    c = ord(match.group())
    return f"\\x{c:02x}" if c < 0x100 else f"\\u{c:04x}"


def shown(text: str) -> str:
    """``text`` with every control character as ``\\xNN`` and invisible reordering or line-breaking
    characters as ``\\uNNNN``: never more than one line, nothing a terminal acts on."""
    return _UNSAFE.sub(_code, text)


def line(text: str) -> str:
    """One line as battgen prints it on a terminal or in a CI log: :func:`shown`, and neither a GitHub
    workflow command at its start nor the runner's legacy ``##[`` command prefix anywhere."""
    text = shown(text)
    if text.lstrip().startswith("::"):
        text = _COMMAND_START.sub(lambda m: m.group(1) + "\\x3a", text, count=1)
    return text.replace("##[", "#\\x23[")


def github_data(text: str) -> str:
    """A workflow command's message, escaped as the Actions runner unescapes it (``%``, CR, LF), other
    control characters as :func:`shown`: it cannot end the command's line."""
    text = _UNSAFE_KEEP_LINES.sub(_code, text)
    return text.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")


def github_property(text: str) -> str:
    """A workflow command's property value (``file=``, ``title=``): :func:`github_data` and the
    property separators ``:`` and ``,``."""
    return github_data(text).replace(":", "%3A").replace(",", "%2C")


def csv_cell(text: str) -> str:
    """A text cell of CSV output that no spreadsheet runs: :func:`shown`, and a leading single quote
    before ``= + - @``, tab or CR (OWASP's CSV injection guard)."""
    return "'" + shown(text) if text.startswith(CSV_TRIGGERS) else shown(text)

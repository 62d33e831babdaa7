"""Schema text as Rust doc comments: one line per paragraph, with the characters rustdoc would read
as markdown links or HTML escaped, so `cargo doc` reads the schema's words as words."""

from __future__ import annotations

import re

# link brackets, HTML, code spans and emphasis by asterisk; an underscore inside a word is plain text
_MARKUP = re.compile(r"([\[\]<>*`\\])")
_URL = re.compile(r"https?://[^\s<>\\]*[^\s<>\\.,;:)]")


def doc_text(text: str) -> str:
    """One line of documentation from schema text (whitespace collapsed, markup escaped)."""
    escaped = _MARKUP.sub(r"\\\1", " ".join(text.split()))
    return _URL.sub(lambda m: f"<{m.group(0)}>", escaped)  # rustdoc links a URL only in angle brackets


def doc_lines(*paragraphs: str, notes: tuple[str, ...] = ()) -> list[str]:
    """The ``///`` lines of a doc comment: the non-empty paragraphs of schema text, then ``notes``
    (our own markdown, not escaped), a blank line between them."""
    out: list[str] = []
    for line in [doc_text(p) for p in paragraphs] + list(notes):
        if not line:
            continue
        if out:
            out.append("")
        out.append(line)
    return out

"""JSON Lines read a block at a time: the values of many lines per step, for a caller that wants no
:class:`~.records.Record` per line (``battgen validate`` builds one only for a line with findings).

What it hands out is what :func:`.documents.read_jsonl` reads from the same file, line for line: the
same values (the standard library's ``json`` is the meaning), the same line numbers and the same
Unreadable lines. In a file longer than a block (shorter ones are read by ``json`` alone, sooner than
orjson is imported) orjson parses a line when it can, and it can only for plain JSON, where it gives
the value ``json`` gives; every other line -- blank, a byte order mark, a syntax error, ``NaN``, a
lone surrogate, a number beyond a double -- is read by ``json`` through :func:`.documents.jsonl_value`,
as :func:`read_jsonl` reads it. The one value orjson reads differently is an integer beyond 64 bits
(a float, where ``json`` keeps the integer): a block holding a run of 19 digits has its lines with
such a run read by ``json``.

A block that is not UTF-8, or holds a line longer than a record may be, is read from its start by
:func:`.documents.jsonl_text_items` (the text reader, which says what is wrong where), and so is the
rest of the file.
"""

from __future__ import annotations

import io
import json
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO, Any

from ..errors import cannot_read
from .documents import BLANK, MAX_LINE, jsonl_text_items, jsonl_value
from .records import InputError, Record, Unreadable

# bytes read at a time (some 17 battery records), and lines parsed at a time: what is parsed stays in the
# processor's cache until it is checked (a megabyte at a time costs a third more), and memory stays flat
BLOCK = 1 << 14
BATCH = 64
Line = tuple[int, object]  # (1-based line, value)
Part = list[Line] | Unreadable

# an integer literal orjson would read as a float has 19 digits or more; digits map to "0", the rest to "x"
_DIGITS = bytes(48 if 48 <= b <= 57 else 120 for b in range(256))
_LONG_RUN = b"0" * 19


_orjson_loads: Callable[[bytes], object] | None = None


def loads_line(line: str) -> object:
    """One line's value as ``json.loads`` reads it, and json's error where it has one: by orjson where it reads
    the line as json does (no run of 19 digits, the module's rule), else by json. For a reader of one line at a
    time (``battgen convert`` on a stream), where :func:`jsonl_blocks` reads a file."""
    global _orjson_loads
    if _orjson_loads is None:
        import orjson

        _orjson_loads = orjson.loads
    raw = line.encode("utf-8", "surrogatepass")  # a lone surrogate: orjson refuses the bytes, json reads the text
    if raw.translate(_DIGITS).find(_LONG_RUN) < 0:
        try:
            return _orjson_loads(raw)
        except json.JSONDecodeError:  # orjson's is one: json reads the line (NaN) or words the error
            pass
    return json.loads(line)


def jsonl_blocks(path: Path, name: str) -> Iterator[Part]:
    """The lines of a JSON Lines file in file order: lists of ``(line, value)`` (blank lines left
    out), and each unreadable line as an Unreadable between them. Raises InputError when the file
    cannot be opened."""
    try:
        stream = path.open("rb")
    except OSError as exc:
        raise InputError(name, 0, cannot_read(exc)) from None
    with stream:
        offset = lineno = 0
        carry = b""
        loads: Callable[[bytes], object] | None = None  # orjson's, once the file is longer than a block
        while True:
            data = stream.read(BLOCK)
            if loads is None and len(data) == BLOCK:
                import orjson  # here: a file of a few records is read sooner by json than orjson is imported

                loads = orjson.loads
            block = carry + data if carry else data
            if not block:
                return
            cut = block.rfind(b"\n") + 1 if data else len(block)  # whole lines; the rest waits for the next block
            if not cut and len(block) <= MAX_LINE:
                carry = block  # a long line, still arriving
                continue
            whole = block[:cut]
            if not cut or not _plain(whole):
                yield from _text_from(path, name, offset, lineno, stream, block)
                return
            long_runs = loads is not None and whole.translate(_DIGITS).find(_LONG_RUN) >= 0
            raws = whole.splitlines(keepends=True)
            for start in range(0, len(raws), BATCH):
                parts, lineno = _lines(raws[start : start + BATCH], name, lineno, long_runs, loads)
                yield from parts
            offset += cut
            carry = block[cut:]
            if not data:
                return


def _plain(block: bytes) -> bool:
    """UTF-8 with no line longer than a record may be (the end of line counted, as the text reader does)."""
    if not block.isascii():
        try:
            block.decode("utf-8")
        except UnicodeDecodeError:
            return False
    return len(block) < MAX_LINE - 2 or max(map(len, block.splitlines(keepends=True))) <= MAX_LINE - 2


def _lines(
    raws: list[bytes], name: str, lineno: int, long_runs: bool, loads: Callable[[bytes], object] | None
) -> tuple[list[Part], int]:
    """Lines of a block (each with its end of line), the first being line ``lineno + 1``: lists of
    values, with each unreadable line an Unreadable between them; and the number of the last line.
    ``long_runs``: the block holds a run of 19 digits somewhere; ``loads``: orjson's (None: json for every line)."""
    out: list[Part] = []
    lines: list[Line] = []
    for raw in raws:
        lineno += 1
        if loads is not None and (not long_runs or raw.translate(_DIGITS).find(_LONG_RUN) < 0):
            try:
                lines.append((lineno, loads(raw)))
                continue
            except json.JSONDecodeError:  # orjson's is one
                pass
        value = jsonl_value(raw.decode("utf-8"), name, lineno)
        if value is BLANK:
            continue
        if isinstance(value, Unreadable):
            if lines:
                out.append(lines)
                lines = []
            out.append(value)
            continue
        lines.append((lineno, value))
    if lines:
        out.append(lines)
    return out, lineno


def _text_from(path: Path, name: str, offset: int, lineno: int, stream: IO[bytes], pending: bytes) -> Iterator[Part]:
    """The rest of the file from ``offset`` (a line's start, line ``lineno + 1``) through the text reader: the file
    opened again there (as the text reader opens it), or, when it cannot seek (a pipe), the bytes read from there
    (``pending``) and then the rest of ``stream``."""
    if stream.seekable():
        try:
            raw = path.open("rb")
        except OSError as exc:
            raise InputError(name, 0, cannot_read(exc)) from None
    else:
        raw = io.BufferedReader(_Rest(pending, stream))
    with raw:
        if stream.seekable():
            raw.seek(offset)
        text = io.TextIOWrapper(raw, encoding="utf-8", newline="")
        try:
            for item in jsonl_text_items(text, name, lineno=lineno):
                if isinstance(item, Record):
                    yield [(item.line, item.data)]
                elif isinstance(item, Unreadable):
                    yield item
        finally:
            text.detach()  # the binary file is closed by its own with


class _Rest(io.RawIOBase):
    """``head``, then what is left of ``stream``."""

    def __init__(self, head: bytes, stream: IO[bytes]) -> None:
        super().__init__()
        self.head = memoryview(head)
        self.stream = stream

    def readable(self) -> bool:
        return True

    def readinto(self, buffer: Any) -> int:
        if self.head:
            n = min(len(buffer), len(self.head))
            buffer[:n] = self.head[:n]
            self.head = self.head[n:]
            return n
        data = self.stream.read(len(buffer))
        buffer[: len(data)] = data
        return len(data)

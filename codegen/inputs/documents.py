"""Text documents as records: JSON (an object or an array of them), JSON Lines and YAML streams.

JSON Lines and YAML are read one record at a time (constant memory): a line, or a YAML document
composed on its own. A JSON document is read whole, but its records are found with
``raw_decode`` positions, and field lines are only worked out for records that ask for them.
YAML goes through PyYAML's safe loader; an alias is walked once when field lines are worked out,
so a document of nested aliases (an "alias bomb") costs no more than its text.

NaN and infinities: JSON's bare ``NaN``/``Infinity``/``-Infinity`` tokens are read as floats; the
strings (:mod:`codegen.ir.numbers`) stay strings, which the generated ``from_dict`` accepts.
A source is a path or an open binary stream (standard input); a byte order mark is skipped.
"""

from __future__ import annotations

import bisect
import io
import json
import re
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from functools import cache
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

from ..errors import cannot_read
from ..text.files import read_text
from .records import TOO_DEEP, InputError, Item, Record, Unreadable, join_path, nearest_line

if TYPE_CHECKING:
    import yaml  # imported where YAML is read: a run reading JSON does without PyYAML

Source = Path | IO[bytes]

_WS = re.compile(r"[ \t\n\r]*")
_DECODER = json.JSONDecoder()
_BOM = "\ufeff"  # a byte order mark some editors write


@contextmanager
def _text_stream(source: Source, name: str) -> Iterator[IO[str]]:
    """``source`` as UTF-8 text, newlines kept as they are; a stream given is left open."""
    if isinstance(source, Path):
        try:
            stream = source.open(encoding="utf-8", newline="")
        except OSError as exc:
            raise InputError(name, 0, cannot_read(exc)) from None
        with stream:
            yield stream
        return
    wrapper = io.TextIOWrapper(source, encoding="utf-8", newline="")
    try:
        yield wrapper
    finally:
        wrapper.detach()  # closing the wrapper would close the caller's stream


def _whole_text(source: Source, name: str) -> str:
    if isinstance(source, Path):
        return read_text(source, name, InputError)
    data = source.read()
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(name, data[: exc.start].count(b"\n") + 1, "expected UTF-8 text") from None


# ------------------------------------------------------------------------------------------------
# JSON Lines: one record per non-blank line, read lazily

# The longest line read as one record: a battery record is a few kilobytes, and a line is held in memory
# (and decoded) whole, so a 200 MB line would cost gigabytes. Longer lines are skipped without being kept.
MAX_LINE = 1 << 20


def _skip_line(stream: IO[str]) -> int:
    """Read on to the end of an over-long line in pieces; how many characters were skipped."""
    skipped = 0
    while True:
        piece = stream.readline(MAX_LINE)
        skipped += len(piece)
        if not piece or piece.endswith("\n"):
            return skipped


def _too_long(length: int) -> str:
    return f"a line of {length} characters, longer than the {MAX_LINE} a JSON Lines record may have (skipped)"


def read_jsonl(source: Source, name: str, *, comments: bool = False) -> Iterator[Item]:
    """One record per non-blank line (with ``comments``, lines starting with ``#`` are skipped
    too); a malformed line is an Unreadable item and reading goes on."""
    with _text_stream(source, name) as stream:
        yield from jsonl_text_items(stream, name, comments=comments)


def jsonl_rows(
    source: Source, name: str, *, comments: bool = False, loads: Callable[[str], object] = json.loads
) -> Iterator[tuple[int, int, object] | Unreadable]:
    """:func:`read_jsonl`'s records as (index, line, value) rows: for a reader that makes a :class:`Record` only
    where it needs one (``battgen convert``: making a frozen Record costs about what reading its line does). ``loads``:
    ``json.loads``, or a faster reader of the same values that raises its errors (convert's)."""
    with _text_stream(source, name) as stream:
        yield from _jsonl_lines(stream, name, comments=comments, loads=loads)


def jsonl_text_items(
    stream: IO[str], name: str, *, comments: bool = False, lineno: int = 0, index: int = 0
) -> Iterator[Item]:
    """:func:`read_jsonl` on an open text stream whose first ``lineno`` lines (holding ``index``
    records) were read already (:mod:`.jsonl_blocks` hands over to it mid-file)."""
    for row in _jsonl_lines(stream, name, comments=comments, lineno=lineno, index=index):
        yield Record(row[0], row[1], row[2], name) if isinstance(row, tuple) else row


def _jsonl_lines(
    stream: IO[str],
    name: str,
    *,
    comments: bool,
    lineno: int = 0,
    index: int = 0,
    loads: Callable[[str], object] = json.loads,
) -> Iterator[tuple[int, int, object] | Unreadable]:
    while True:
        try:
            line = stream.readline(MAX_LINE + 1)
            if len(line) > MAX_LINE and not line.endswith("\n"):
                lineno += 1
                length = len(line) + _skip_line(stream)
                yield Unreadable(name, lineno, _too_long(length))
                continue
        except UnicodeDecodeError:
            yield Unreadable(name, lineno + 1, "expected UTF-8 text")
            return
        if not line:
            return
        lineno += 1
        value = jsonl_value(line, name, lineno, comments=comments, loads=loads)
        if value is BLANK:
            continue
        if isinstance(value, Unreadable):
            yield value
            continue
        yield index, lineno, value
        index += 1


BLANK = object()  # jsonl_value's answer for a blank (or comment) line


def jsonl_value(
    line: str, name: str, lineno: int, *, comments: bool = False, loads: Callable[[str], object] = json.loads
) -> object:
    """The value of one JSON Lines line (its end of line kept: an error's column counts it),
    :data:`BLANK` for a line holding none, or the Unreadable saying why it cannot be read."""
    if lineno == 1 and line.startswith(_BOM):
        line = line[1:]
    text = line.strip()
    if not text or (comments and text.startswith("#")):
        return BLANK
    try:
        return loads(line)
    except json.JSONDecodeError as exc:
        message = f"expected one JSON value per line: {exc.msg} (column {exc.colno})"
        return Unreadable(name, lineno, message, exc.msg, exc.colno)
    except RecursionError:
        return Unreadable(name, lineno, TOO_DEEP)
    except ValueError:  # an integer of more digits than Python converts
        return Unreadable(name, lineno, _long_number(line))


# ------------------------------------------------------------------------------------------------
# JSON: one object or an array of objects


class _LineIndex:
    """Offset -> 1-based line over a text, by binary search of its newline offsets."""

    def __init__(self, text: str, start: int, end: int, first_line: int) -> None:
        self.start = start
        self.first_line = first_line
        self.newlines = [m.start() for m in re.finditer("\n", text[start:end])]

    def line(self, offset: int) -> int:
        return self.first_line + bisect.bisect_right(self.newlines, offset - self.start - 1)


def read_json(source: Source, name: str) -> Iterator[Item]:
    """The records of a JSON document: each element of a top-level array, else the one value.
    The whole document is checked before the first record (InputError when it is malformed)."""
    text = _whole_text(source, name)
    try:
        return _json_records(text, name)
    except json.JSONDecodeError as exc:
        message = f"malformed JSON: {exc.msg} (column {exc.colno})"
        raise InputError(name, exc.lineno, message, reason=exc.msg, column=exc.colno) from None
    except RecursionError:
        raise InputError(name, 1, TOO_DEEP) from None
    except ValueError:  # an integer of more digits than Python converts (4,300)
        raise InputError(name, _long_number_line(text), _long_number(text)) from None


_LONG_NUMBER = re.compile(r"[0-9]{4000,}")


def _long_number_line(text: str) -> int:
    m = _LONG_NUMBER.search(text)
    return text.count("\n", 0, m.start()) + 1 if m else 0


def _long_number(text: str) -> str:
    m = _LONG_NUMBER.search(text)
    digits = f"{m.end() - m.start()} digits" if m else "too many digits"
    return f"expected a number a battery field can hold, got an integer of {digits} (more than 4,300 cannot be read)"


def _skip(text: str, pos: int) -> int:
    """The offset after the whitespace at ``pos``."""
    return _WS.match(text, pos).end()  # type: ignore[union-attr]  # the pattern matches the empty string


def _json_records(text: str, name: str) -> Iterator[Item]:
    pos = _skip(text, 1 if text.startswith(_BOM) else 0)
    records: list[tuple[int, int, object]] = []  # start offset, end offset, value
    if text.startswith("[", pos):
        pos = _skip(text, pos + 1)
        if text.startswith("]", pos):
            pos += 1
        else:
            while True:
                value, end = _DECODER.raw_decode(text, pos)
                records.append((pos, end, value))
                pos = _skip(text, end)
                if text.startswith(",", pos):
                    pos = _skip(text, pos + 1)
                    continue
                if text.startswith("]", pos):
                    pos += 1
                    break
                raise json.JSONDecodeError("expected ',' or ']' after an array element", text, pos)
    else:
        value, end = _DECODER.raw_decode(text, pos)
        records.append((pos, end, value))
        pos = end
    pos = _skip(text, pos)
    if pos != len(text):
        raise json.JSONDecodeError("expected the end of the file after the JSON document", text, pos)
    return _json_items(text, name, records)


def _json_items(text: str, name: str, records: list[tuple[int, int, object]]) -> Iterator[Item]:
    line, counted = 1, 0
    for index, (start, end, value) in enumerate(records):
        line += text.count("\n", counted, start)
        counted = start
        yield Record(index, line, value, name, locate=_json_locator(text, start, end, line))


def _json_locator(text: str, start: int, end: int, line: int) -> Callable[[str], int | None]:
    cache: dict[str, int] = {}

    def locate(path: str) -> int | None:
        if not cache:
            index = _LineIndex(text, start, end, line)
            try:
                _scan_json(text, start, "", cache, index)
            except (json.JSONDecodeError, IndexError, RecursionError):
                cache[""] = line  # already decoded once, so this does not happen; stay quiet if it does
        return nearest_line(cache, path)

    return locate


def _scan_json(text: str, pos: int, path: str, out: dict[str, int], index: _LineIndex) -> int:
    """Walk one JSON value from ``pos`` recording the line of every path; returns its end offset."""
    out[path] = index.line(pos)
    char = text[pos]
    if char == "{":
        pos = _skip(text, pos + 1)
        if text[pos] == "}":
            return pos + 1
        while True:
            key, pos = _DECODER.raw_decode(text, pos)
            pos = _skip(text, _skip(text, pos) + 1)  # past the ':'
            pos = _scan_json(text, pos, join_path(path, str(key)), out, index)
            pos = _skip(text, pos)
            if text[pos] == "}":
                return pos + 1
            pos = _skip(text, pos + 1)  # past the ','
    if char == "[":
        pos = _skip(text, pos + 1)
        if text[pos] == "]":
            return pos + 1
        item = 0
        while True:
            pos = _scan_json(text, pos, f"{path}[{item}]", out, index)
            item += 1
            pos = _skip(text, pos)
            if text[pos] == "]":
                return pos + 1
            pos = _skip(text, pos + 1)
    _, end = _DECODER.raw_decode(text, pos)
    return int(end)


# ------------------------------------------------------------------------------------------------
# YAML: a stream of documents, each a record or a list of records; composed one document at a time


@cache
def _line_loader() -> Any:
    """SafeLoader that also hands back the composed node, so each value's line is known (a class made
    on first use, with PyYAML imported then)."""
    import yaml

    class LineLoader(yaml.SafeLoader):
        def next_document(self) -> tuple[object, yaml.Node] | None:
            if not self.check_node():
                return None
            node = self.get_node()
            if node is None:
                return None
            return self.construct_document(node), node

        def construct_long_int(self, node: yaml.ScalarNode) -> object:
            """PyYAML's int, but an integer of more digits than Python converts is an error at its line."""
            try:
                return self.construct_yaml_int(node)
            except ValueError:
                digits = sum(c.isdigit() for c in str(node.value))
                problem = f"an integer of {digits} digits is more than a battery field holds (4,300 cannot be read)"
                raise yaml.constructor.ConstructorError(None, None, problem, node.start_mark) from None

    LineLoader.add_constructor("tag:yaml.org,2002:int", LineLoader.construct_long_int)
    return LineLoader


def _node_lines(node: yaml.Node, path: str, out: dict[str, int], seen: set[int]) -> None:
    import yaml

    out.setdefault(path, node.start_mark.line + 1)
    if id(node) in seen:
        return  # an alias: its lines are those of the anchored node, walked once (no alias bombs)
    seen.add(id(node))
    if isinstance(node, yaml.MappingNode):
        for key_node, value_node in node.value:
            if isinstance(key_node, yaml.ScalarNode):
                key = join_path(path, str(key_node.value))
                out.setdefault(key, key_node.start_mark.line + 1)
                _node_lines(value_node, key, out, seen)
    elif isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            _node_lines(item, f"{path}[{i}]", out, seen)


def _yaml_locator(node: yaml.Node) -> Callable[[str], int | None]:
    cache: dict[str, int] = {}

    def locate(path: str) -> int | None:
        if not cache:
            try:
                _node_lines(node, "", cache, set())
            except RecursionError:
                cache.setdefault("", node.start_mark.line + 1)
        return nearest_line(cache, path)

    return locate


def _yaml_error(name: str, exc: Exception) -> InputError:
    import yaml

    if isinstance(exc, yaml.MarkedYAMLError):
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else 0
        what = " ".join(p for p in (exc.context, exc.problem) if p)
        column = mark.column + 1 if mark is not None else 0
        return InputError(name, line, f"malformed YAML: {what}", reason=what, column=column)
    if isinstance(exc, yaml.YAMLError):
        return InputError(name, 0, f"malformed YAML: {exc}", reason=str(exc))
    return InputError(name, 0, "expected UTF-8 text")


def read_yaml(source: Source, name: str) -> Iterator[Item]:
    """One record per document, or per item of a document that is a list; empty documents are
    skipped. A malformed document raises InputError when reading reaches it."""
    import yaml

    with _text_stream(source, name) as stream:
        try:
            loader = _line_loader()(stream)
        except (yaml.YAMLError, UnicodeDecodeError) as exc:
            raise _yaml_error(name, exc) from None
        try:
            index = 0
            while True:
                try:
                    document = loader.next_document()
                except (yaml.YAMLError, UnicodeDecodeError) as exc:
                    raise _yaml_error(name, exc) from None
                except RecursionError:
                    raise InputError(name, loader.line + 1, TOO_DEEP) from None
                if document is None:
                    return
                data, node = document
                if data is None:
                    continue  # an empty document
                if isinstance(node, yaml.SequenceNode) and isinstance(data, list):
                    for item, item_data in zip(node.value, data, strict=True):
                        yield Record(index, item.start_mark.line + 1, item_data, name, locate=_yaml_locator(item))
                        index += 1
                else:
                    yield Record(index, node.start_mark.line + 1, data, name, locate=_yaml_locator(node))
                    index += 1
        finally:
            loader.dispose()

"""Reading data files into records for ``battgen validate``: JSON, YAML, JSON Lines, devicetree,
parameter files (.param/.parm/.params), PX4 ULog (.ulg) and MAVLink logs (.tlog, raw .mav streams).

Each record keeps the line it starts on and, on demand, the line of any field path inside it,
so a violation can be reported as ``file:line: message``. JSON Lines and YAML streams are read
one record at a time (constant memory); a JSON document is read whole, but its records are
found with ``raw_decode`` positions and field lines are only worked out for records that need them.
NaN and infinities: JSON's bare ``NaN``/``Infinity``/``-Infinity`` tokens and the strings
``"NaN"``/``"Infinity"``/``"-Infinity"`` are both accepted (the generated ``from_dict`` reads the strings).
The binary logs and parameter files are read by the ``instances_*`` modules; their records carry a
decoded instance, a ``location`` (timestamp, multi_id, offset, ...) and the fields not to check.
"""

from __future__ import annotations

import bisect
import json
import re
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

import yaml

from ..errors import BattgenError, LocatedError
from ..ir import Message, SourceFormat
from ..text.files import read_text

JSON_SUFFIXES = frozenset({".json"})
JSONL_SUFFIXES = frozenset({".jsonl", ".ndjson"})
YAML_SUFFIXES = frozenset({".yaml", ".yml"})
DTS_SUFFIXES = frozenset({".dts", ".dtsi"})
DTB_SUFFIXES = frozenset({".dtb"})
PARAM_SUFFIXES = frozenset({".param", ".parm", ".params"})
ULOG_SUFFIXES = frozenset({".ulg"})
TLOG_SUFFIXES = frozenset({".tlog"})
MAVLINK_SUFFIXES = frozenset({".mav"})  # not .bin: that is ArduPilot's DataFlash log
KNOWN_SUFFIXES = JSON_SUFFIXES | JSONL_SUFFIXES | YAML_SUFFIXES | DTS_SUFFIXES | DTB_SUFFIXES
KNOWN_SUFFIXES |= PARAM_SUFFIXES | ULOG_SUFFIXES | TLOG_SUFFIXES | MAVLINK_SUFFIXES
_KINDS = (
    ("json", JSON_SUFFIXES),
    ("jsonl", JSONL_SUFFIXES),
    ("yaml", YAML_SUFFIXES),
    ("dts", DTS_SUFFIXES),
    ("dtb", DTB_SUFFIXES),
    ("param", PARAM_SUFFIXES),
    ("ulog", ULOG_SUFFIXES),
    ("tlog", TLOG_SUFFIXES),
    ("mavlink", MAVLINK_SUFFIXES),
)
KINDS = tuple(kind for kind, _ in _KINDS)
# the source format a file kind implies (for a default --message); the text formats imply none
KIND_FORMATS = {"dts": "devicetree", "dtb": "devicetree", "param": "params", "ulog": "uorb"}
KIND_FORMATS |= {"tlog": "mavlink", "mavlink": "mavlink"}

if TYPE_CHECKING:
    from . import devicetree as dts

TOO_DEEP = "values nested too deeply to read"
_WS = re.compile(r"[ \t\n\r]*")
_DECODER = json.JSONDecoder()
_PATH_TOKEN = re.compile(r"\[\d+\]|[^.\[]+")


class InstanceError(LocatedError):
    """A data file that cannot be read at all: names the file, the 1-based line and what was expected."""


@dataclass(frozen=True)
class Record:
    """One instance read from a file: the plain data ``from_dict`` takes and where it came from."""

    index: int  # 0-based position among the file's records
    line: int  # 1-based line where the record starts
    data: object
    file: str  # the file to report (a devicetree node may come from an included file)
    where: str = ""  # extra location words, e.g. a devicetree node path
    locate: Callable[[str], int | None] | None = field(default=None, compare=False)
    instance: Any = field(default=None, compare=False)  # already decoded (binary logs): no from_dict
    skip: frozenset[str] = frozenset()  # fields the source lacks: their checks are not reported
    location: Mapping[str, object] | None = None  # machine-readable where: timestamp, multi_id, offset...

    def line_of(self, path: str) -> int:
        """The line of a field path (``voltage_cell_v[3]``, ``timestamp.usec``), else the record's."""
        if self.locate is not None:
            found = self.locate(path)
            if found is not None:
                return found
        return self.line


@dataclass(frozen=True)
class Unreadable:
    """A part of a file that could not be read (a malformed JSON line); reading goes on after it."""

    file: str
    line: int
    message: str


@dataclass(frozen=True)
class Notice:
    """Something to know about a whole input, not a violation of a record: how a log's format
    differs from the schema, fields left unchecked, damage skipped in a stream. ``warning``
    notices are printed; ``info`` ones only go into the JSON report."""

    file: str
    message: str
    kind: str  # "format-diff", "unchecked", "stream", "damage", "empty"
    severity: str = "warning"
    data: Mapping[str, object] | None = None


Item = Record | Unreadable | Notice


def file_kind(path: Path) -> str:
    """The data format (one of KINDS) from the file name's extension."""
    suffix = path.suffix.lower()
    for kind, suffixes in _KINDS:
        if suffix in suffixes:
            return kind
    known = ", ".join(sorted(KNOWN_SUFFIXES))
    raise InstanceError(
        path.as_posix(),
        0,
        f"cannot tell the data format from the extension (expected one of {known}, or give --input-format)",
    )


def read_records(
    path: Path, message: Message, display: str | None = None, *, model: Any = None, kind: str | None = None
) -> Iterator[Item]:
    """The records of one data file, in file order. Raises InstanceError (or another LocatedError)
    when the file is unreadable. ``model`` is the generated class of ``message``: parameter files
    and binary logs need it; ``kind`` overrides the format the extension implies."""
    name = display if display is not None else path.as_posix()
    kind = kind or file_kind(path)
    if kind in ("param", "ulog", "tlog", "mavlink"):
        if model is None:
            raise InstanceError(name, 0, f"reading {kind} input needs the generated class of {message.qualified_name}")
        return _read_binary_kind(path, name, message, model, kind)
    if kind in ("dts", "dtb"):
        if message.format is not SourceFormat.DEVICETREE:
            raise InstanceError(
                name,
                0,
                f"a devicetree file holds devicetree nodes, but {message.qualified_name} is a "
                f"{message.format.value} message",
            )
        return _read_devicetree(path, name, message, binary=kind == "dtb")
    if kind == "jsonl":
        return _read_jsonl(path, name)
    if kind == "yaml":
        return _read_yaml(path, name)
    return _read_json(path, name)


def _read_binary_kind(path: Path, name: str, message: Message, model: Any, kind: str) -> Iterator[Item]:
    expected = {"param": SourceFormat.PARAMS, "ulog": SourceFormat.UORB}.get(kind, SourceFormat.MAVLINK)
    if message.format is not expected:
        what = {"param": "a parameter file holds parameters", "ulog": "a ULog file holds uORB topics"}.get(
            kind, "a MAVLink log holds MAVLink messages"
        )
        raise InstanceError(name, 0, f"{what}, but {message.qualified_name} is a {message.format.value} message")
    if kind == "param":
        from .param_records import read_params

        return read_params(path, name, message, model)
    if kind == "ulog":
        from .ulog import ulog_items

        return ulog_items(path, name, message, model)
    from .tlog import mavlink_items

    return mavlink_items(path, name, message, model, timestamps=kind == "tlog")


# ------------------------------------------------------------------------------------------------
# shared helpers


def split_path(path: str) -> list[str]:
    """``a.b[3].c`` -> ``['a', 'b', '[3]', 'c']``."""
    return _PATH_TOKEN.findall(path)


def join_path(parent: str, token: str) -> str:
    if not parent:
        return token
    return parent + token if token.startswith("[") else f"{parent}.{token}"


def _lookup(lines: Mapping[str, int], path: str) -> int | None:
    """The line of ``path``, else of its nearest enclosing path that has one."""
    tokens = split_path(path)
    while tokens:
        prefix = ""
        for token in tokens:
            prefix = join_path(prefix, token)
        found = lines.get(prefix)
        if found is not None:
            return found
        tokens.pop()
    return None


def _open_text(path: Path, name: str) -> TextIO:
    try:
        return path.open(encoding="utf-8", newline="")
    except OSError as exc:
        raise InstanceError(name, 0, f"cannot read file: {exc.strerror or exc}") from None


def _read_text(path: Path, name: str) -> str:
    return read_text(path, name, InstanceError)


# ------------------------------------------------------------------------------------------------
# JSON Lines: one record per non-blank line, read lazily


def _read_jsonl(path: Path, name: str) -> Iterator[Item]:
    stream = _open_text(path, name)
    with stream:
        index = 0
        lineno = 0
        while True:
            try:
                line = stream.readline()
            except UnicodeDecodeError:
                yield Unreadable(name, lineno + 1, "expected UTF-8 text")
                return
            if not line:
                return
            lineno += 1
            if lineno == 1 and line.startswith("\ufeff"):
                line = line[1:]  # a byte order mark some editors write
            if not line.strip():
                continue
            try:
                data = json.loads(line)
            except json.JSONDecodeError as exc:
                yield Unreadable(name, lineno, f"expected one JSON value per line: {exc.msg} (column {exc.colno})")
                continue
            except RecursionError:
                yield Unreadable(name, lineno, TOO_DEEP)
                continue
            yield Record(index, lineno, data, name)
            index += 1


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


def _read_json(path: Path, name: str) -> Iterator[Item]:
    text = _read_text(path, name)
    try:
        return _json_records(text, name)
    except json.JSONDecodeError as exc:
        raise InstanceError(name, exc.lineno, f"malformed JSON: {exc.msg} (column {exc.colno})") from None
    except RecursionError:
        raise InstanceError(name, 1, TOO_DEEP) from None


def _json_records(text: str, name: str) -> Iterator[Item]:
    start = 1 if text.startswith("\ufeff") else 0  # a byte order mark some editors write
    pos = _WS.match(text, start).end()  # type: ignore[union-attr]  # the pattern matches the empty string
    records: list[tuple[int, int, object]] = []  # start offset, end offset, value
    if text.startswith("[", pos):
        pos = _WS.match(text, pos + 1).end()  # type: ignore[union-attr]
        if text.startswith("]", pos):
            pos += 1
        else:
            while True:
                value, end = _DECODER.raw_decode(text, pos)
                records.append((pos, end, value))
                pos = _WS.match(text, end).end()  # type: ignore[union-attr]
                if text.startswith(",", pos):
                    pos = _WS.match(text, pos + 1).end()  # type: ignore[union-attr]
                    continue
                if text.startswith("]", pos):
                    pos += 1
                    break
                raise json.JSONDecodeError("expected ',' or ']' after an array element", text, pos)
    else:
        value, end = _DECODER.raw_decode(text, pos)
        records.append((pos, end, value))
        pos = end
    pos = _WS.match(text, pos).end()  # type: ignore[union-attr]
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
        return _lookup(cache, path)

    return locate


def _scan_json(text: str, pos: int, path: str, out: dict[str, int], index: _LineIndex) -> int:
    """Walk one JSON value from ``pos`` recording the line of every path; returns its end offset."""
    out[path] = index.line(pos)
    char = text[pos]
    if char == "{":
        pos = _WS.match(text, pos + 1).end()  # type: ignore[union-attr]
        if text[pos] == "}":
            return pos + 1
        while True:
            key, pos = _DECODER.raw_decode(text, pos)
            pos = _WS.match(text, pos).end() + 1  # type: ignore[union-attr]  # past the ':'
            pos = _WS.match(text, pos).end()  # type: ignore[union-attr]
            pos = _scan_json(text, pos, join_path(path, str(key)), out, index)
            pos = _WS.match(text, pos).end()  # type: ignore[union-attr]
            if text[pos] == "}":
                return pos + 1
            pos = _WS.match(text, pos + 1).end()  # type: ignore[union-attr]  # past the ','
    if char == "[":
        pos = _WS.match(text, pos + 1).end()  # type: ignore[union-attr]
        if text[pos] == "]":
            return pos + 1
        item = 0
        while True:
            pos = _scan_json(text, pos, f"{path}[{item}]", out, index)
            item += 1
            pos = _WS.match(text, pos).end()  # type: ignore[union-attr]
            if text[pos] == "]":
                return pos + 1
            pos = _WS.match(text, pos + 1).end()  # type: ignore[union-attr]
    _, end = _DECODER.raw_decode(text, pos)
    return int(end)


# ------------------------------------------------------------------------------------------------
# YAML: a stream of documents, each a record or a list of records; composed one document at a time


class _LineLoader(yaml.SafeLoader):
    """SafeLoader that also hands back the composed node, so each value's line is known."""

    def next_document(self) -> tuple[object, yaml.Node] | None:
        if not self.check_node():
            return None
        node = self.get_node()
        if node is None:
            return None
        return self.construct_document(node), node


def _node_lines(node: yaml.Node, path: str, out: dict[str, int], seen: set[int]) -> None:
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
        return _lookup(cache, path)

    return locate


def _yaml_error(name: str, exc: yaml.YAMLError) -> InstanceError:
    if isinstance(exc, yaml.MarkedYAMLError):
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else 0
        what = " ".join(p for p in (exc.context, exc.problem) if p)
        return InstanceError(name, line, f"malformed YAML: {what}")
    return InstanceError(name, 0, f"malformed YAML: {exc}")


def _read_yaml(path: Path, name: str) -> Iterator[Item]:
    stream = _open_text(path, name)
    with stream:
        try:
            loader = _LineLoader(stream)
        except (yaml.YAMLError, UnicodeDecodeError) as exc:
            raise _as_input_error(name, exc) from None
        try:
            index = 0
            while True:
                try:
                    document = loader.next_document()
                except (yaml.YAMLError, UnicodeDecodeError) as exc:
                    raise _as_input_error(name, exc) from None
                except RecursionError:
                    raise InstanceError(name, loader.line + 1, TOO_DEEP) from None
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


def _as_input_error(name: str, exc: Exception) -> InstanceError:
    if isinstance(exc, yaml.YAMLError):
        return _yaml_error(name, exc)
    return InstanceError(name, 0, "expected UTF-8 text")


# ------------------------------------------------------------------------------------------------
# devicetree: nodes compatible with the binding, turned into the model's plain data


def _read_devicetree(path: Path, name: str, message: Message, *, binary: bool) -> Iterator[Item]:
    from . import devicetree as dts

    nodes = dts.read_dtb(path) if binary else dts.read_dts(path)  # DevicetreeError names file and line
    return _dt_items(name, message, dts.nodes_for_message(nodes, message))


def _dt_items(name: str, message: Message, nodes: list[dts.DtNode]) -> Iterator[Item]:
    from . import devicetree as dts

    for index, node in enumerate(nodes):
        file = node.file or name
        try:
            data = dts.node_to_model_dict(node, message)
        except BattgenError as exc:
            yield Unreadable(file, node.line, f"{node.path}: {exc}")
            continue
        yield Record(index, node.line, data, file, where=node.path, locate=_dt_locator(node))


def _dt_locator(node: dts.DtNode) -> Callable[[str], int | None]:
    def locate(path: str) -> int | None:
        tokens = split_path(path)
        value = node.properties.get(tokens[0]) if tokens else None
        return value.line if value is not None and value.line > 0 else None

    return locate

"""What the data readers hand out: records, the parts that could not be read, and notices.

Every reader (:mod:`.documents`, :mod:`.ulog`, :mod:`.tlog`, :mod:`.parameter_records`,
:mod:`.devicetree.records`) yields :data:`Item`\\ s in file order, and raises :class:`InputError`
(or another LocatedError naming file and line) when a file cannot be read at all. A record keeps
the line it starts on and, on demand, the line of any field path inside it, so that a violation
can be reported as ``file:line: message``; records of binary logs carry the decoded instance and a
machine-readable ``location`` instead.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from ..errors import LocatedError
from .model import GeneratedMessage

TOO_DEEP = "values nested too deeply to read"
_PATH_TOKEN = re.compile(r"\[\d+\]|[^.\[]+")


class InputError(LocatedError):
    """A data file that cannot be read at all: names the file, the 1-based line and what was expected.

    ``reason`` is the parser's own account when a syntax error stopped it (JSON's ``Expecting
    value``), for a caller that words its own message; ``column`` is 1-based, 0 when unknown."""

    def __init__(self, file: str, line: int, message: str, *, reason: str = "", column: int = 0) -> None:
        super().__init__(file, line, message)
        self.reason = reason
        self.column = column


@dataclass(frozen=True)
class Record:
    """One record read from a file: the plain data ``from_dict`` takes and where it came from."""

    index: int  # 0-based position among the file's records
    line: int  # 1-based line where the record starts (0: a binary input, located by ``where``)
    data: object
    file: str  # the file to report (a devicetree node may come from an included file)
    where: str = ""  # extra location words, e.g. a devicetree node path or a log record's topic
    locate: Callable[[str], int | None] | None = field(default=None, compare=False)
    instance: GeneratedMessage | None = field(default=None, compare=False)  # decoded already: no from_dict
    skip: frozenset[str] = frozenset()  # fields the source lacks: their checks are not reported
    location: Mapping[str, object] | None = None  # machine-readable where: timestamp, multi_id, offset...
    extras: Mapping[str, object] | None = None  # a log's values the instance has no field for (older PX4)
    context: Mapping[str, object] | None = field(default=None, compare=False)  # a parameter set's other values
    # decoded with the instance: the other messages of a multi-message side (a CAN node's BatteryInfoAux)
    companions: tuple[GeneratedMessage | None, ...] = field(default=(), compare=False)

    def line_of(self, path: str) -> int:
        """The line of a field path (``voltage_cell_v[3]``, ``timestamp.usec``), else the record's."""
        if self.locate is not None:
            found = self.locate(path)
            if found is not None:
                return found
        return self.line


@dataclass(frozen=True)
class Unreadable:
    """A part of a file that could not be read (a malformed JSON line); reading goes on after it.

    ``reason`` and ``column`` as in :class:`InputError`."""

    file: str
    line: int
    message: str
    reason: str = ""
    column: int = 0


@dataclass(frozen=True)
class Notice:
    """Something to know about a whole input, not a violation of a record: how a log's format
    differs from the schema, fields left unchecked, damage skipped in a stream. ``warning``
    notices are printed; ``info`` ones only go into the JSON report."""

    file: str
    message: str
    kind: str  # "format-diff", "unchecked", "unfit", "stream", "damage", "empty"
    severity: str = "warning"
    data: Mapping[str, object] | None = None


Item = Record | Unreadable | Notice


def split_path(path: str) -> list[str]:
    """``a.b[3].c`` -> ``['a', 'b', '[3]', 'c']``."""
    return _PATH_TOKEN.findall(path)


def join_path(parent: str, token: str) -> str:
    """``join_path('a.b', '[3]')`` -> ``a.b[3]``; ``join_path('a', 'c')`` -> ``a.c``."""
    if not parent:
        return token
    return parent + token if token.startswith("[") else f"{parent}.{token}"


def nearest_line(lines: Mapping[str, int], path: str) -> int | None:
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


def first_field_locator(lines: Mapping[str, int]) -> Callable[[str], int | None]:
    """A locator for flat records (parameter sets, devicetree nodes): a path's first name's line."""

    def locate(path: str) -> int | None:
        tokens = split_path(path)
        return lines.get(tokens[0]) if tokens else None

    return locate

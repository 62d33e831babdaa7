"""YAML loading for the schema frontends (devicetree bindings, mappings, rules): safe_load
semantics, plus the line of every node.

Mappings load as :class:`YMap` (a dict that knows its own line and the line of each key) and
sequences as :class:`YList`, so errors and IR locations can point at the source line.
"""

from __future__ import annotations

from collections.abc import Hashable, Iterable, Sequence
from typing import Any

import yaml

from ..errors import SchemaError


class YMap(dict[Any, Any]):
    """A mapping with ``line`` (where it starts) and ``key_lines`` (where each key is)."""

    line: int = 0

    def __init__(self) -> None:
        super().__init__()
        self.key_lines: dict[Any, int] = {}

    def line_of(self, key: str) -> int:
        return self.key_lines.get(key, self.line)


class YList(list[Any]):
    """A sequence with ``line`` (where it starts) and ``item_lines`` (where each item is)."""

    line: int = 0

    def __init__(self, items: Iterable[Any] = ()) -> None:
        super().__init__(items)
        self.item_lines: list[int] = []


try:  # libyaml's parser when present: same safe constructor, several times faster
    from yaml import CSafeLoader as _SafeBase
except ImportError:  # pragma: no cover - PyYAML built without libyaml
    from yaml import SafeLoader as _SafeBase  # type: ignore[assignment]


class _Loader(_SafeBase):
    """SafeLoader whose maps and sequences remember lines and reject duplicate keys."""


def _construct_map(loader: _Loader, node: yaml.MappingNode) -> YMap:
    loader.flatten_mapping(node)
    out = YMap()
    out.line = node.start_mark.line + 1
    for key_node, value_node in node.value:
        key = loader.construct_object(key_node, deep=True)
        if not isinstance(key, Hashable):
            raise yaml.constructor.ConstructorError(None, None, "expected a scalar key", key_node.start_mark)
        if key in out:
            raise yaml.constructor.ConstructorError(None, None, f"duplicate key {key!r}", key_node.start_mark)
        out[key] = loader.construct_object(value_node, deep=True)
        out.key_lines[key] = key_node.start_mark.line + 1
    return out


def _construct_seq(loader: _Loader, node: yaml.SequenceNode) -> YList:
    out = YList(loader.construct_object(child, deep=True) for child in node.value)
    out.line = node.start_mark.line + 1
    out.item_lines = [child.start_mark.line + 1 for child in node.value]
    return out


_Loader.add_constructor("tag:yaml.org,2002:map", _construct_map)
_Loader.add_constructor("tag:yaml.org,2002:seq", _construct_seq)


def line_at(doc: Any, path: Sequence[Any]) -> int:
    """The line of the deepest value along ``path`` (keys and indexes) whose line is known."""
    line = getattr(doc, "line", 1) or 1
    node = doc
    for step in path:
        if isinstance(node, YMap) and step in node:
            line = node.line_of(step)
        elif isinstance(node, YList) and isinstance(step, int) and 0 <= step < len(node):
            line = node.item_lines[step]
        else:
            break
        node = node[step]
    return line


def load(text: str, display: str, expected: str = "well-formed YAML") -> Any:
    """Parse one YAML document; YAML errors become SchemaError at the problem's line, saying
    ``expected <expected>: <problem>``."""
    try:
        return yaml.load(text, Loader=_Loader)  # _Loader is a SafeLoader subclass
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else 1
        what = exc.problem or exc.context or "malformed YAML"
        raise SchemaError(display, line, f"expected {expected}: {what}") from None
    except yaml.YAMLError as exc:
        raise SchemaError(display, 1, f"expected {expected}: {exc}") from None
    except RecursionError:
        raise SchemaError(display, 1, "expected YAML without runaway nesting") from None

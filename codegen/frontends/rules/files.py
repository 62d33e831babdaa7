"""One rule file (YAML) read into :class:`~codegen.ir.CrossFieldRule`\\ s: checked against
``rules.schema.json`` beside this module, every expression parsed, loop variables resolved.

Any problem is a :class:`~codegen.errors.SchemaError` naming the file and the line of the key at fault.
"""

from __future__ import annotations

import json
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any

import jsonschema

from ...errors import SchemaError
from ...ir import CrossFieldRule, Location
from ...ir.expr import Expr, Loop, RuleExpressions
from ...text.files import display_path
from ...text.limits import read_schema_text
from ...text.yaml_lines import YList, YMap, line_at
from ...text.yaml_lines import load as load_yaml
from .binding import scoped
from .parse import ExprError, parse, parse_binding, parse_template

SCHEMA_FILE = "rules.schema.json"


@cache
def _schema() -> dict[str, Any]:
    text = resources.files(__package__).joinpath(SCHEMA_FILE).read_text(encoding="utf-8")
    data: dict[str, Any] = json.loads(text)
    return data


def load_rule_file(path: Path, *, root: Path | None = None) -> tuple[CrossFieldRule, ...]:
    """The rules of one file; ``root`` shortens the file name in errors and locations."""
    display = display_path(path, root)
    data = load_yaml(read_schema_text(path, display), display, expected="YAML")
    if data is None:
        raise SchemaError(display, 1, "expected a rule file (a mapping with 'messages' and 'rules'), found nothing")
    errors = sorted(jsonschema.Draft202012Validator(_schema()).iter_errors(data), key=lambda e: list(e.path))
    if errors:
        err = jsonschema.exceptions.best_match(errors)
        at = "/".join(str(p) for p in err.absolute_path) or "the file"
        raise SchemaError(
            display,
            line_at(data, list(err.absolute_path)),
            f"{at}: {err.message} (see codegen/frontends/rules/{SCHEMA_FILE})",
        )
    assert isinstance(data, YMap)
    messages = tuple(data["messages"])
    return tuple(_rule(item, messages, display) for item in data["rules"])


def _rule(item: YMap, messages: tuple[str, ...], file: str) -> CrossFieldRule:
    raw_for = item.get("for", [])
    loops = (raw_for,) if isinstance(raw_for, str) else tuple(raw_for)
    keyed = [(str(k), item.line_of(k)) for k in item]
    if isinstance(raw_for, YList):
        keyed += [(f"for[{j}]", line) for j, line in enumerate(raw_for.item_lines)]
    location = Location(file, item.line)
    where: str | None = item.get("where")
    path: str | None = item.get("path")
    check: str = item["assert"]
    message: str = item["message"]
    return CrossFieldRule(
        id=item["id"],
        messages=messages,
        severity=item.get("severity", "error"),
        check=check,
        location=location,
        exprs=_parsed(_Source(location, dict(keyed)), check, where, loops, path, message),
        doc=item.get("doc", ""),
        where=where,
        loops=loops,
        path=path,
        message=message,
        lines=tuple(keyed),
    )


class _Source:
    """Where a rule's keys are, for parse errors."""

    def __init__(self, location: Location, lines: dict[str, int]) -> None:
        self.location = location
        self.lines = lines

    def error(self, key: str, text: str) -> SchemaError:
        # ``for[2]`` falls back to ``for`` (a single loop written as a string), then to the rule's line
        line = self.lines.get(key, self.lines.get(key.split("[")[0], self.location.line))
        return SchemaError(self.location.file, line, text)


def _parsed(
    src: _Source, check: str, where: str | None, loops: tuple[str, ...], path: str | None, message: str
) -> RuleExpressions:
    """The rule's expressions parsed (loops, message, where, assert, path: the first error is reported)."""

    def expr(text: str, key: str) -> Expr:
        try:
            return parse(text)
        except ExprError as exc:
            raise src.error(key, f"in '{key}' {text!r}: {exc.message} at column {exc.column}") from None

    bindings: list[Loop] = []
    for j, text in enumerate(loops):
        try:
            bindings.append(parse_binding(text))
        except ExprError as exc:
            raise src.error(f"for[{j}]", f"in 'for' {text!r}: {exc.message} at column {exc.column}") from None
    try:
        template = parse_template(message)
    except ExprError as exc:
        raise src.error("message", f"in 'message': {exc.message} at column {exc.column}") from None
    parsed = RuleExpressions(
        where=expr(where, "where") if where is not None else None,
        loops=tuple(bindings),
        check=expr(check, "assert"),
        path=expr(path, "path") if path is not None else None,
        message=template,
    )
    return scoped(parsed)

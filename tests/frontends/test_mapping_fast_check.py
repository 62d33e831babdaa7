"""The compiled check of the bundled mapping files accepts and refuses exactly what jsonschema does.

On every bundled mapping file, the error fixtures (the fuzz crashers of ``schema-mappings`` and the
broken files of test_mappings), and deterministic mutations of every node of every bundled file
(wrong types, missing and unknown keys, bad names, repeated items), the compiled check of
:mod:`codegen.frontends.mappings.fast_check` and jsonschema's Draft 2020-12 validator on the same
JSON Schema give the same verdict. A bundled file the fast check refuses still gets jsonschema's
error (the same ``file:line: expected ...``), and a user's file always goes through jsonschema.
"""

from __future__ import annotations

import copy
import math
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import jsonschema
import pytest
from conftest import ROOT

from codegen.apps.battery.catalog import build_catalog, bundled_catalog
from codegen.apps.schemas.package import bundled_schemas
from codegen.errors import SchemaError
from codegen.frontends import mappings
from codegen.frontends.loader import load
from codegen.frontends.mappings import fast_check
from codegen.text.yaml_lines import load as load_yaml

BUNDLED = sorted((ROOT / "schemas" / "mappings").glob("*.yaml"))
CRASHERS = sorted((ROOT / "tests" / "fuzz" / "crashers" / "schema-mappings").glob("*.yaml"))

# broken files of the kinds tests/frontends/test_mappings.py writes (each refused by the schema)
_RULE = "mappings:\n- name: m\n  source: a\n  target: concepts\n  rules:\n  - {rule}\n"
BROKEN = [
    "",
    "concepts: 3\n",
    "extra: {}\n",
    "concepts:\n  Voltage: {kind: number}\n",
    "concepts:\n  v: {kind: float}\n",
    "concepts:\n  v: {kind: choice, choices: [a, a]}\n",
    "concepts:\n  v: {kind: choice, choices: []}\n",
    "endpoints:\n  a: {messages: {}}\n",
    "endpoints:\n  a: {messages: {b: params.X}}\n",
    "endpoints:\n  a: {messages: {b: uorb.}}\n",
    "mappings:\n- {name: m, source: a, rules: []}\n",
    _RULE.format(rule="{op: frobnicate, to: v, from: x}"),
    _RULE.format(rule="{op: copy, to: v, from: x, scale: 2}"),
    _RULE.format(rule="{op: copy, to: [], from: x}"),
    _RULE.format(rule="{op: copy, to: '', from: x}"),
    _RULE.format(rule="{op: copy, from: x}"),
    _RULE.format(rule="{op: copy, to: v, from: x, only: sideways}"),
    _RULE.format(rule="{op: flags, to: v, from: x}"),
    _RULE.format(rule="{op: flags, to: v, from: x, map: {}}"),
    _RULE.format(rule="{op: scale, to: v, from: x, factor: yes}"),
    _RULE.format(rule="{op: scale, to: v, from: x, factor: '2'}"),
]

# values a node is replaced with: each JSON type, and strings the schema's patterns care about
_VALUES: list[Any] = [None, True, 0, 1.5, math.nan, "", "x", "NaN", "Bad-Name", [], ["x"], {}, {"x": 1}, -math.inf]


_JSONSCHEMA = jsonschema.Draft202012Validator(mappings.mappings_json_schema())


def _jsonschema_accepts(doc: Any) -> bool:
    return bool(_JSONSCHEMA.is_valid(doc))


def _agree(doc: Any) -> bool:
    return fast_check.mapping_file_check()(doc) == _jsonschema_accepts(doc)


def _nodes(value: Any, path: tuple[Any, ...] = ()) -> Iterator[tuple[tuple[Any, ...], Any]]:
    yield path, value
    if isinstance(value, dict):
        for key, item in value.items():
            yield from _nodes(item, (*path, key))
    elif isinstance(value, list):
        for i, item in enumerate(value):
            yield from _nodes(item, (*path, i))


def _plain(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_plain(v) for v in value]
    return value


def _part(doc: dict[str, Any], path: tuple[Any, ...]) -> dict[str, Any]:
    """The smallest document holding the node at ``path``: one mapping, concept or endpoint (the
    schema checks each on its own, so the verdict is the whole file's; jsonschema stays quick)."""
    if len(path) < 2:
        return copy.deepcopy(doc)
    section, key = path[0], path[1]
    if section == "mappings":
        mapping = copy.deepcopy(doc["mappings"][key])
        if len(path) >= 4 and path[2] == "rules":  # one rule of it
            mapping["rules"] = [mapping["rules"][path[3]]]
        return {"mappings": [mapping]}
    return {section: {key: copy.deepcopy(doc[section][key])}}


def _set(doc: Any, path: tuple[Any, ...], value: Any) -> None:
    for step in path[:-1]:
        doc = doc[step]
    doc[path[-1]] = value


def _at(doc: Any, path: tuple[Any, ...]) -> Any:
    for step in path:
        doc = doc[step]
    return doc


def _local(path: tuple[Any, ...]) -> tuple[Any, ...]:
    """``path`` inside :func:`_part`'s document."""
    if len(path) < 2:
        return path
    if path[0] != "mappings":
        return path
    if len(path) >= 4 and path[2] == "rules":
        return ("mappings", 0, "rules", 0, *path[4:])
    return ("mappings", 0, *path[2:])


def _mutations(doc: dict[str, Any]) -> Iterator[Any]:
    """Deterministic variants of ``doc``, each changing one node."""
    for i, (path, value) in enumerate(_nodes(doc)):
        if path:
            for v in (_VALUES[i % len(_VALUES)], _VALUES[(i + 5) % len(_VALUES)]):
                part = _part(doc, path)
                _set(part, _local(path), copy.deepcopy(v))
                yield part
        if isinstance(value, dict):
            for key in list(value)[:3]:
                part = _part(doc, path)
                del _at(part, _local(path))[key]
                yield part
            part = _part(doc, path)
            _at(part, _local(path))["zz_unknown"] = 1
            yield part
            if value:
                part = _part(doc, path)
                node = _at(part, _local(path))
                first = next(iter(node))
                node["Bad-Name"] = node.pop(first)
                yield part
        elif isinstance(value, list) and value:
            part = _part(doc, path)
            node = _at(part, _local(path))
            node.append(copy.deepcopy(node[0]))
            yield part
            part = _part(doc, path)
            _at(part, _local(path)).clear()
            yield part


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: p.name)
def test_every_bundled_file_is_accepted_by_both(path: Path) -> None:
    doc = load_yaml(path.read_text(encoding="utf-8"), path.name)
    assert fast_check.mapping_file_check()(doc) and _jsonschema_accepts(doc)


@pytest.mark.parametrize("path", CRASHERS, ids=lambda p: p.name)
def test_fuzz_fixtures_get_the_same_verdict(path: Path) -> None:
    assert _agree(load_yaml(path.read_text(encoding="utf-8"), path.name))


@pytest.mark.parametrize("text", BROKEN)
def test_broken_files_are_refused_by_both(text: str) -> None:
    doc = load_yaml(text, "m.yaml")
    if isinstance(doc, dict):
        assert not fast_check.mapping_file_check()(doc) and not _jsonschema_accepts(doc)


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: p.name)
def test_every_mutation_of_a_bundled_file_gets_the_same_verdict(path: Path) -> None:
    doc = _plain(load_yaml(path.read_text(encoding="utf-8"), path.name))
    check = fast_check.mapping_file_check()
    verdicts = [(v, _jsonschema_accepts(v)) for v in _mutations(doc)]
    assert not all(ok for _, ok in verdicts), "the mutations should break the file somewhere"
    disagree = [v for v, ok in verdicts if check(v) != ok]
    assert not disagree, disagree[:3]


def test_unknown_keywords_are_not_ignored() -> None:
    with pytest.raises(TypeError, match="not compiled"):
        fast_check._Compiler({}).compile({"maxLength": 3})


def test_bundled_files_skip_jsonschema_and_user_files_do_not(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[str] = []
    monkeypatch.setattr(mappings, "_validate", lambda doc, display: calls.append(display))
    schema = load([bundled_schemas()], only=(*mappings.MAPPED_FORMATS,))
    mappings.parse_dir(bundled_schemas() / "mappings", schema=schema)
    assert calls == []
    (tmp_path / "m.yaml").write_text("concepts:\n  v: {kind: number}\n")
    mappings.parse_dir(tmp_path)
    assert calls == ["m.yaml"]


@pytest.mark.parametrize("text", BROKEN[1:])
def test_a_bundled_file_the_fast_check_refuses_gets_jsonschemas_error(
    text: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "m.yaml").write_text(text)
    errors = []
    for bundled in (tmp_path, tmp_path / "elsewhere"):  # the fast path, then jsonschema alone
        monkeypatch.setattr(mappings, "_BUNDLED_DIR", bundled)
        with pytest.raises(SchemaError) as info:
            mappings.parse_dir(tmp_path)
        errors.append(str(info.value))
    assert errors[0] == errors[1] and "m.yaml:" in errors[0] and "expected" in errors[0]


def test_mapped_formats_are_the_formats_an_endpoint_may_name() -> None:
    pattern = mappings.mappings_json_schema()["$defs"]["endpoint"]["properties"]["messages"]["additionalProperties"]
    formats = re.fullmatch(r"\^\(([a-z|]+)\).*", pattern["pattern"])
    assert formats is not None and tuple(formats.group(1).split("|")) == mappings.MAPPED_FORMATS


def test_the_bundled_catalog_is_the_catalog_of_the_whole_folder() -> None:
    whole = build_catalog(load([bundled_schemas()]))
    ours = bundled_catalog()
    assert ours.concepts == whole.concepts
    assert ours.sources == whole.sources and ours.companions == whole.companions
    for name in [*ours.sources, *ours.companions]:
        assert ours.schema.message(name) == whole.schema.message(name)

    def first(schema_enums: Any, entry: str) -> Any:  # how a rule's constant is looked up (columnar.py)
        return next((e for e in schema_enums if any(x.name == entry for x in e.entries)), None)

    names = {x.name for e in ours.schema.enums for x in e.entries}
    assert all(first(ours.schema.enums, n) == first(whole.schema.enums, n) for n in names)

"""The IR cache of a schema folder (codegen.frontends.cache): the same IR as a parse, read back only under
its own key, never half-written, and a folder's change or a foreign file never served."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from conftest import ROOT

from codegen.apps.battery import catalog
from codegen.errors import BattgenError
from codegen.frontends import cache, loader
from codegen.frontends.mappings import MAPPED_FORMATS
from codegen.ir import json_form

SCHEMAS = ROOT / "schemas"


def _no_parse(*_args: object, **_kwargs: object) -> None:
    raise AssertionError("parsed, though the cache held this folder's IR")


def test_cached_ir_is_the_parsed_ir_and_is_read_back(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    only = ("uorb", "dronecan", "devicetree", "mavlink", "cyphal", "mappings")
    parsed = loader.load([SCHEMAS], only=only)
    first = cache.load_cached(SCHEMAS, tmp_path, only=only)
    assert json_form.dumps(first) == json_form.dumps(parsed)
    assert first.warnings == parsed.warnings
    (stored,) = tmp_path.iterdir()
    monkeypatch.setattr(loader, "load", _no_parse)
    again = cache.load_cached(SCHEMAS, tmp_path, only=only)
    assert json_form.dumps(again) == json_form.dumps(parsed)
    # equal as objects too: the frontends' one NaN object survives the pickle, so ops and sentinels holding
    # NaN compare equal (a fresh pickle float per NaN made the cached IR unequal to the parsed one)
    assert again == parsed
    assert list(tmp_path.iterdir()) == [stored]  # nothing written when the cache was fresh


def test_a_changed_file_or_selection_is_parsed_again(tmp_path: Path) -> None:
    folder = tmp_path / "schemas"
    shutil.copytree(SCHEMAS / "uorb", folder / "uorb")
    store = tmp_path / "cache"
    before = cache.load_cached(folder, store)
    key = cache.cache_key(folder)
    assert cache.cache_key(folder, only=("uorb",)) != key
    msg = next(folder.glob("uorb/*.msg"))
    msg.write_text(msg.read_text(encoding="utf-8") + "uint8 added_by_the_test\n", encoding="utf-8")
    assert cache.cache_key(folder) != key
    after = cache.load_cached(folder, store)
    changed = {m.qualified_name: m for m in after.messages}
    assert any(f.name == "added_by_the_test" for m in changed.values() for f in m.fields)
    assert not any(f.name == "added_by_the_test" for m in before.messages for f in m.fields)


def test_a_file_under_another_key_or_torn_is_never_loaded(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    folder = tmp_path / "schemas"
    shutil.copytree(SCHEMAS / "uorb", folder / "uorb")
    store = tmp_path / "cache"
    cache.load_cached(folder, store)
    (stored,) = store.iterdir()
    good = stored.read_bytes()
    parses: list[object] = []
    real_load = loader.load

    def counting_load(*args: object, **kwargs: object) -> object:
        parses.append(args)
        return real_load(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(loader, "load", counting_load)
    key = cache.cache_key(folder).encode()
    other = good.replace(key, b"0" * len(key), 1)  # a pickle of some IR, under a key that is not this folder's
    for bad in (other, good[: len(good) // 2], b"", b"not a cache at all"):
        stored.write_bytes(bad)
        schema = cache.load_cached(folder, store)
        assert schema.messages
    assert len(parses) == 4
    assert stored.read_bytes() == good  # rewritten whole each time


def test_an_unwritable_cache_folder_still_loads(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("a file where the cache folder would be", encoding="utf-8")
    folder = tmp_path / "schemas"
    shutil.copytree(SCHEMAS / "uorb", folder / "uorb")
    assert cache.load_cached(folder, blocker / "battgen").messages
    assert blocker.read_text(encoding="utf-8").startswith("a file")


def test_a_schema_error_is_raised_on_every_run(tmp_path: Path) -> None:
    folder = tmp_path / "schemas"
    (folder / "uorb").mkdir(parents=True)
    (folder / "uorb" / "Broken.msg").write_text("not_a_type field\n", encoding="utf-8")
    for _ in range(2):
        with pytest.raises(BattgenError, match=r"Broken\.msg"):
            cache.load_cached(folder, tmp_path / "cache")
    assert not (tmp_path / "cache").exists() or not any((tmp_path / "cache").iterdir())


def test_the_catalog_reads_what_the_mappings_name() -> None:
    # written in catalog.py so that a fresh cache imports no frontend
    assert catalog._MAPPED_FORMATS == MAPPED_FORMATS
    assert catalog._MAPPINGS_DIR == loader.MAPPINGS_DIR

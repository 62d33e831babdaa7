"""Shared fixtures: the repository root and helpers to render a generated package into a temp dir."""

from __future__ import annotations

import importlib
import os
import sys
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import pytest
from hypothesis import HealthCheck, settings

from codegen.backends.python.writer import generate
from codegen.ir import Schema

ROOT = Path(__file__).resolve().parent.parent

# Property tests run on shared 2-core machines: no per-example deadline, and in CI the same
# examples every run (a red CI must be reproducible); locally they stay random to find new cases.
settings.register_profile("battgen", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("battgen-ci", parent=settings.get_profile("battgen"), derandomize=True, database=None)
settings.load_profile("battgen-ci" if os.environ.get("CI") else "battgen")


@pytest.fixture(autouse=True, scope="session")
def _own_ir_cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    """The bundled schemas' IR cache (codegen.frontends.cache) in a folder of this run, for in-process and
    subprocess commands alike: the suite neither reads nor writes the user's ~/.cache/battgen."""
    before = os.environ.get("XDG_CACHE_HOME")
    os.environ["XDG_CACHE_HOME"] = str(tmp_path_factory.mktemp("xdg-cache"))
    yield
    if before is None:
        os.environ.pop("XDG_CACHE_HOME", None)
    else:
        os.environ["XDG_CACHE_HOME"] = before


@pytest.fixture
def import_generated(tmp_path: Path) -> Iterator[object]:
    """Generate a Schema into a fresh package under tmp_path and import one of its modules."""
    added: list[str] = []

    def _import(schema: Schema, module: str = "", package: str = "genpkg") -> ModuleType:
        generate(schema, tmp_path / package)
        if str(tmp_path) not in sys.path:
            sys.path.insert(0, str(tmp_path))
            added.append(str(tmp_path))
        importlib.invalidate_caches()
        return importlib.import_module(f"{package}.{module}" if module else package)

    yield _import
    for entry in added:
        sys.path.remove(entry)
    for name in [m for m in sys.modules if m == "genpkg" or m.startswith("genpkg.")]:
        del sys.modules[name]

"""The toolchain uses only the public API of the runtime it generates (``generated/_ulog*.py`` and
the other runtime modules): a private name (``_step``, ``_by_id``...) of that code is the
runtime's own business, free to change with it, so ``codegen/inputs`` and ``codegen/apps`` never
reach for one; the ULog index walks logs through ``Log``'s walking API instead."""

from __future__ import annotations

import ast
import re
from pathlib import Path

from codegen.inputs.ulog import index as ulog_index
from generated import _ulog

ROOT = Path(__file__).resolve().parents[2]
RUNTIME = ROOT / "codegen" / "backends" / "python" / "runtime"
USERS = [ROOT / "codegen" / "inputs", ROOT / "codegen" / "apps"]
# Private names of other libraries that a runtime name happens to share: not the runtime's.
FOREIGN = {"_timestamp"}  # pymavlink's receive time of a message (the runtime's ULog Writer has one too)


def _private(name: str) -> bool:
    return len(name) > 1 and name.startswith("_") and not name.startswith("__")


def runtime_private_names() -> set[str]:
    """Every private name the runtime modules define: module and class members, ``self._x`` attributes."""
    names: set[str] = set()
    for path in RUNTIME.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
                names.add(node.name)
            elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
                names.add(node.id)
            elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store):
                names.add(node.attr)
    return {n for n in names if _private(n)} - FOREIGN


def private_uses(source: str, private: set[str]) -> list[str]:
    """Attributes of other objects than ``self``/``cls`` named as a runtime's private names, and
    ``getattr(x, "_name")`` of them, in ``source``: ``line: name``."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Attribute) and node.attr in private:
            if not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls")):
                found.append(f"{node.lineno}: {node.attr}")
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in ("getattr", "hasattr"):
            if len(node.args) > 1 and isinstance(node.args[1], ast.Constant) and node.args[1].value in private:
                found.append(f"{node.lineno}: {node.args[1].value}")
    return sorted(found, key=lambda f: int(f.split(":")[0]))


def test_the_toolchain_uses_no_private_name_of_the_generated_runtime() -> None:
    private = runtime_private_names()
    assert {"_by_id", "_streams", "_fresh", "_adopt", "_windows"} <= private  # the scan sees the runtime's privates
    offenders = {
        str(path.relative_to(ROOT)): uses
        for folder in USERS
        for path in sorted(folder.rglob("*.py"))
        if (uses := private_uses(path.read_text(encoding="utf-8"), private))
    }
    assert not offenders, offenders


def test_the_check_finds_what_it_looks_for() -> None:
    private = runtime_private_names()
    source = "def f(log, walk):\n    log._fresh()\n    self._fresh()\n    return getattr(walk, '_by_id', None)\n"
    assert private_uses(source, private) == ["2: _fresh", "4: _by_id"]


def test_the_compiled_walk_and_the_runtime_agree_on_what_a_corrupt_header_is() -> None:
    """The C walk hard-codes the bound the runtime names (it stops before a header the runtime
    would call corrupt, so the runtime decides): the two must not drift apart."""
    source = (ROOT / "codegen" / "inputs" / "ulog" / "_scan.c").read_text(encoding="utf-8")
    bound = re.search(r"#define MAX_UNKNOWN_SIZE (\d+)", source)
    assert bound is not None and int(bound.group(1)) == _ulog.MAX_UNKNOWN_SIZE
    assert _ulog.Log.KNOWN_TYPES == _ulog.KNOWN_TYPES == frozenset(b"ABCDFILMOPQRS")
    assert ulog_index._known_types(_ulog.read(_ulog.MAGIC + bytes(9), index=False)) == bytes(
        1 if t in _ulog.KNOWN_TYPES else 0 for t in range(256)
    )

"""The layers hold: import-linter's contract (pyproject.toml) passes, and no module imports itself
back through others.

The contract says who may import whom (cli > apps > inputs | frontends | backends > text > errors > ir)
and forbids cycles between siblings; the second test closes the gap the contract leaves, a cycle
between a package and its own submodules. Both read every import, function-level ones included.
"""

from __future__ import annotations

import subprocess
import sys

import grimp
import pytest
from conftest import ROOT

TOP_LEVEL = ("ir", "errors", "text", "frontends", "backends", "inputs", "apps", "cli")


def test_layer_contract() -> None:
    script = "import sys; from importlinter.cli import lint_imports_command; sys.exit(lint_imports_command())"
    proc = subprocess.run([sys.executable, "-c", script], cwd=ROOT, capture_output=True, text=True, check=False)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "0 broken" in proc.stdout, proc.stdout


def test_no_import_cycles() -> None:
    graph = grimp.build_graph("codegen")
    cycles = sorted(
        f"{importer} -> {imported} -> ... -> {importer}"
        for importer in graph.modules
        for imported in graph.find_modules_directly_imported_by(importer)
        if graph.chain_exists(importer=imported, imported=importer)
    )
    assert cycles == []


@pytest.mark.parametrize("layer", TOP_LEVEL)
def test_root_holds_only_the_layers(layer: str) -> None:
    """codegen/ holds the package face (__init__, __main__), errors.py and one folder per layer."""
    root = ROOT / "codegen"
    modules = {p.name for p in root.glob("*.py")}
    assert modules == {"__init__.py", "__main__.py", "errors.py"}
    assert layer == "errors" or (root / layer / "__init__.py").is_file()

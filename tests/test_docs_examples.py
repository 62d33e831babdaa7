"""Every example of the README and the documentation runs as written, on the files that ship in docs/examples/.

Each ``sh`` block of README.md and docs/**/*.md is run line by line with ``battgen`` on the PATH (as after
``. .venv/bin/activate``), from a fresh folder holding a copy of docs/examples/ (commands write their outputs
there); an ``output`` block right after an ``sh`` block lists lines the block must print. A line ending in
``# exit N`` must exit N, every other 0. The README's two set-up commands (before its ``---``) are CI's own
(tests/test_readme.py). ``text`` blocks are not run (a live bus, a Dask cluster, a long fuzz run).
The binary examples are checked to be what ``docs/examples/make_examples.py`` writes.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ROOT

EXAMPLES = ROOT / "docs" / "examples"
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
BLOCK = re.compile(r"```(sh|output)\n(.*?)```", re.S)
SETUP = ("python3 -m venv",)  # the README's own set-up lines, run by CI (.ci/run), not here


def blocks(page: Path) -> list[tuple[list[str], list[str]]]:
    """The page's ``sh`` blocks, each with the lines of the ``output`` block right after it (if any)."""
    text = page.read_text(encoding="utf-8")
    found: list[tuple[list[str], list[str]]] = []
    for m in BLOCK.finditer(text):
        lines = [x for x in m.group(2).splitlines() if x.strip()]
        if m.group(1) == "sh":
            found.append(([x for x in lines if not x.startswith(SETUP)], []))
        else:
            assert found and not found[-1][1], f"{page}: an output block that follows no sh block"
            found[-1][1].extend(lines)
    return found


def test_every_page_with_commands_is_found() -> None:
    with_commands = {p.relative_to(ROOT).as_posix() for p in PAGES if any(c for c, _ in blocks(p))}
    assert {"README.md", "docs/getting-started.md", "docs/commands/validate.md", "docs/fleet.md"} <= with_commands


@pytest.mark.parametrize("page", [p for p in PAGES if any(c for c, _ in blocks(p))],
                         ids=lambda p: p.relative_to(ROOT).as_posix())  # fmt: skip
def test_page_commands_run_as_written(page: Path, tmp_path: Path) -> None:
    shutil.copytree(EXAMPLES, tmp_path / "docs" / "examples")
    (tmp_path / "schemas").symlink_to(ROOT / "schemas")  # pages that name a bundled schema file
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}")
    for commands, expected in blocks(page):
        printed: list[str] = []
        for command in commands:
            assert command.startswith("battgen "), f"{page.name}: not a battgen command: {command}"
            want = re.search(r"# exit (\d)\s*$", command)
            proc = subprocess.run(["bash", "-c", command], cwd=tmp_path, env=env, capture_output=True, text=True,
                                  timeout=600, check=False)  # fmt: skip
            assert proc.returncode == (int(want.group(1)) if want else 0), f"{command}\n{proc.stderr[-2000:]}"
            assert "Traceback" not in proc.stderr, command
            printed += proc.stdout.splitlines() + proc.stderr.splitlines()
        missing = [x for x in expected if x not in printed]
        assert missing == [], f"{page.name}: {commands}"


def test_binary_examples_are_what_the_documented_command_writes(tmp_path: Path) -> None:
    pytest.importorskip("can")  # bench.log is written by python-can's candump writer
    proc = subprocess.run([sys.executable, str(EXAMPLES / "make_examples.py"), str(tmp_path)],
                          capture_output=True, text=True, timeout=300, check=False)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    written = sorted(p.name for p in tmp_path.iterdir())
    assert written == ["bench.log", "cyphal-bench.txt", "flight.bin", "flight.ulg"]
    for name in written:
        assert (tmp_path / name).read_bytes() == (EXAMPLES / name).read_bytes(), name

"""The generated package laid out by ``ruff format`` itself, as one step of generation.

Emitters write each statement on one line; ruff (a pinned dependency of battgen) breaks the ones that
do not fit and normalises quotes and numbers, so generated/ reads as reviewed code without battgen
following ruff's style by hand. The settings are passed whole and ``--isolated`` keeps any ruff
configuration found on disk out, so the output depends on the IR and the ruff version alone.
"""

from __future__ import annotations

import sys
from pathlib import Path

from ...errors import BattgenError

LINE_LENGTH = 120  # the project's line length (pyproject.toml [tool.ruff]), which generated/ is checked against
TARGET_VERSION = "py311"
_SETTINGS = ("--isolated", "--line-length", str(LINE_LENGTH), "--target-version", TARGET_VERSION)


def ruff_command(*args: str) -> list[str]:
    """``ruff`` with the generated package's settings: the interpreter's own, so the pinned version."""
    return [sys.executable, "-m", "ruff", *args, *_SETTINGS]


def ruff_format(files: dict[str, str]) -> dict[str, str]:
    """``files`` (relative path -> text) with every ``.py`` formatted by ruff, in one run over a
    temporary folder (one process, not one per module); other files are returned as they are."""
    sources = {rel: text for rel, text in files.items() if rel.endswith(".py")}
    if not sources:
        return dict(files)
    import subprocess  # here, not at the top: a data command imports this module for its names alone
    import tempfile

    with tempfile.TemporaryDirectory(prefix="battgen-ruff-") as tmp:
        root = Path(tmp)
        for rel, text in sources.items():
            path = root / rel
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text, encoding="utf-8")
        # the files named one by one: ruff formats a named file even where its default excludes
        # (a folder called ``build`` or ``dist``) would skip it in a folder walk
        try:
            done = subprocess.run(
                [*ruff_command("format", "--no-cache", "--quiet"), *sorted(sources)],
                cwd=root,
                capture_output=True,
                text=True,
                check=False,
            )
        except OSError as exc:
            raise BattgenError(f"ruff: could not run {sys.executable} -m ruff: {exc}") from exc
        if done.returncode != 0:
            problem = (done.stderr or done.stdout).strip()[:2000]
            if "No module named ruff" in problem:
                raise BattgenError("ruff: not installed; expected the ruff package (a battgen dependency) to format")
            raise BattgenError(f"ruff format: failed on the generated package: {problem}")
        formatted = {rel: (root / rel).read_text(encoding="utf-8") for rel in sources}
    return {rel: formatted.get(rel, text) for rel, text in files.items()}

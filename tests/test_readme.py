"""The README's two set-up commands stay true: CI runs the test one verbatim."""

from __future__ import annotations

import re

from conftest import ROOT


def _commands() -> list[str]:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    top = text.split("---", 1)[0]
    return re.findall(r"```sh\n(.+?)\n```", top, flags=re.S)


def test_readme_top_has_two_commands() -> None:
    main_job, tests = _commands()
    assert "battgen generate" in main_job and "pip install" in main_job
    assert "pytest" in tests and "pip install" in tests


def test_ci_runs_the_readme_test_command() -> None:
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert _commands()[1] in ci.splitlines()

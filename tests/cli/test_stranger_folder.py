"""battgen run inside a stranger's folder holding ``schemas/`` and ``generated/``: the project's
bundled schemas and generated package come from where battgen is installed, never from the current
folder, and nothing of that folder is imported (its ``generated/__init__.py`` would leave a marker
file and raise). Each command gives the same exit code and output there as in an empty folder,
run both as the ``battgen`` script and as ``python -m`` (which puts the current folder on sys.path)."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ROOT

MARKER = "IMPORTED-A-STRANGERS-CODE"
RECORDS = ROOT / "tests" / "data" / "instances" / "uorb_records.jsonl"
COMMANDS = {
    "validate": ["validate", "--message", "uorb.BatteryStatus", "x.jsonl"],
    "convert": ["convert", "--from", "uorb.BatteryStatus", "--to", "concepts", "--allow-empty", "one.jsonl"],
    "export": ["export", "-q", "-o", "out", "x.jsonl", "--message", "uorb.BatteryStatus"],
    "report": ["report", "--message", "uorb.BatteryStatus", "-o", "r.html", "x.jsonl"],
    "failsafe": ["failsafe", "--message", "uorb.BatteryStatus", "--allow-empty", "x.jsonl"],
    "params": ["params", "--check", "b.param"],
    "generate --check": ["generate", "--check"],
    "list": ["list"],
}


def _folder(base: Path, stranger: bool) -> Path:
    base.mkdir()
    shutil.copy(RECORDS, base / "x.jsonl")
    (base / "one.jsonl").write_text(json.dumps({"voltage_v": 16.4, "remaining": 0.5}) + "\n", encoding="utf-8")
    (base / "b.param").write_text("BATT_MONITOR 4\nBATT_LOW_VOLT 14.0\nBATT_CRT_VOLT 13.2\n", encoding="utf-8")
    if stranger:
        (base / "schemas" / "uorb").mkdir(parents=True)
        (base / "schemas" / "uorb" / "BatteryStatus.msg").write_text("not a message definition\n", encoding="utf-8")
        (base / "generated").mkdir()
        (base / "generated" / "__init__.py").write_text(
            f"import pathlib\npathlib.Path({str(base / MARKER)!r}).write_text('ran')\nraise SystemExit(97)\n",
            encoding="utf-8",
        )
    return base


def _run(folder: Path, args: list[str], as_module: bool) -> tuple[int, str]:
    script = Path(sys.executable).with_name("battgen")
    command = [sys.executable, "-m", "codegen.cli.main", *args] if as_module else [str(script), *args]
    done = subprocess.run(command, cwd=folder, capture_output=True, text=True, timeout=300)
    return done.returncode, (done.stdout + done.stderr).replace(str(folder), "FOLDER")


@pytest.mark.parametrize("as_module", [False, True], ids=["script", "python -m"])
def test_a_strangers_folder_is_data_not_code(tmp_path: Path, as_module: bool) -> None:
    stranger, plain = _folder(tmp_path / "stranger", True), _folder(tmp_path / "plain", False)
    for name, args in COMMANDS.items():
        got = _run(stranger, args, as_module)
        assert not (stranger / MARKER).exists(), f"{name}: imported the folder's generated/"
        expected = _run(plain, args, as_module)
        assert got == expected, name
        assert got[0] != 97, name
    valid = ["validate", "--message", "uorb.BatteryStatus", "one.jsonl"]
    got = _run(stranger, valid, as_module)
    assert got == _run(plain, valid, as_module) and got[0] in (0, 1) and "1 record" in got[1]  # the bundled schemas
    assert _run(stranger, COMMANDS["list"], as_module)[0] == 0
    assert _run(stranger, COMMANDS["generate --check"], as_module)[0] == 0

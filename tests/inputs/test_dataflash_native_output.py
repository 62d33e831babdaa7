"""pymavlink's C indexer writes to the process's own stderr (``Invalid length in FMT message at 0``) where no Python
redirection sees it: battgen takes that text as the reader's notes, so a damaged log puts nothing of pymavlink's
between battgen's own lines (a CI log, a terminal) and nothing on a JSON standard output."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from codegen.inputs.dataflash.log import _fd_captured


def _damaged(tmp_path: Path) -> Path:
    path = tmp_path / "damaged.bin"
    # a FMT message header whose length byte is 0: pymavlink's indexer complains in C
    path.write_bytes(bytes([0xA3, 0x95, 0x80, 0x80, 0x00]) + bytes(range(256)) * 2)
    return path


def test_a_damaged_logs_native_messages_stay_off_the_output(tmp_path: Path) -> None:
    log = _damaged(tmp_path)
    run = subprocess.run(
        [sys.executable, "-m", "codegen", "report", "--format", "json", str(log)],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert run.returncode == 1, run.stderr
    assert run.stdout == ""
    assert "Invalid length" not in run.stderr
    expected = f"{log}: expected battery records, found none (--allow-empty accepts that)"
    assert run.stderr.strip().splitlines() == [expected]


def test_the_capture_gives_back_what_c_code_wrote_and_restores_the_descriptors(
    capfd: pytest.CaptureFixture[str],
) -> None:
    with _fd_captured() as native:
        os.write(2, b"from C on stderr\n")
        os.write(1, b"from C on stdout\n")
    assert native().splitlines() == ["from C on stderr", "from C on stdout"]
    os.write(2, b"after\n")
    assert "after" in capfd.readouterr().err

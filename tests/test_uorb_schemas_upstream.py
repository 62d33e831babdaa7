"""The shipped PX4 battery schemas are PX4's own files of today: ``schemas/uorb/BatteryStatus.msg``
and ``BatteryInfo.msg`` equal the copies of PX4 main in ../shared/corpus/upstream/px4_msgs/main/ byte for
byte, apart from the two ``# Upstream:`` lines that name where they come from."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from shared_data import UPSTREAM

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = ROOT / "schemas" / "uorb"
CORPUS = UPSTREAM / "px4_msgs"
UPSTREAM = ("BatteryStatus", "BatteryInfo")


def without_provenance(text: str) -> str:
    """The file as upstream has it: our '# Upstream:' note (two comment lines and a blank) taken out."""
    return re.sub(r"# Upstream: [^\n]*\n# [^\n]*\n\n", "", text, count=1)


@pytest.mark.parametrize("name", UPSTREAM)
def test_shipped_file_is_px4_mains(name: str) -> None:
    ours = (SHIPPED / f"{name}.msg").read_text(encoding="utf-8")
    upstream = (CORPUS / "main" / f"{name}.msg").read_text(encoding="utf-8")
    assert ours != upstream, "the shipped file names its upstream source"
    assert without_provenance(ours) == upstream


@pytest.mark.parametrize("name", UPSTREAM)
def test_provenance_names_the_corpus_commit(name: str) -> None:
    note = re.search(r"# Upstream: PX4-Autopilot (\S+), as px4_msgs main (\w+) ", (SHIPPED / f"{name}.msg").read_text())
    assert note is not None
    source = (CORPUS / "SOURCE.md").read_text(encoding="utf-8")
    main_row = next(line for line in source.splitlines() if line.startswith("| `main/`"))
    assert note.group(2) in main_row and name in note.group(1)


def test_v0_is_the_message_version_0_layout() -> None:
    """BatteryStatusV0 is kept as shipped: PX4's MESSAGE_VERSION 0 with serial_number, 4 instances."""
    text = (SHIPPED / "BatteryStatusV0.msg").read_text(encoding="utf-8")
    assert "uint32 MESSAGE_VERSION = 0\n" in text and "uint16 serial_number " in text
    assert "uint8 MAX_INSTANCES = 4\n" in text

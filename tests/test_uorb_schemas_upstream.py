"""The shipped PX4 battery schemas hold PX4's facts in our words: ``schemas/uorb/BatteryStatus.msg`` and
``BatteryInfo.msg`` against PX4 main's files in ../shared/corpus/upstream/px4_msgs/main/, ``BatteryStatusV0.msg``
against PX4's MESSAGE_VERSION 0 file (../shared/corpus/realworld2/px4/BatteryStatusV0.upstream.msg).

Facts: field names, types and order, units, ranges, invalid markers, enums and their kinds, constants, the
message version and PX4's struct layout (offsets, sizes, padding: what a ULog record is). Only the descriptions
differ (tests/test_schemas_own_words.py checks they are not PX4's)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from schema_facts import facts
from shared_data import SHARED, UPSTREAM, require

from codegen.frontends import uorb

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = ROOT / "schemas" / "uorb"
CORPUS = UPSTREAM / "px4_msgs"
SOURCES = {
    "BatteryStatus": CORPUS / "main" / "BatteryStatus.msg",
    "BatteryInfo": CORPUS / "main" / "BatteryInfo.msg",
    "BatteryStatusV0": SHARED / "corpus" / "realworld2" / "px4" / "BatteryStatusV0.upstream.msg",
}


def _upstream_as_ours(name: str, folder: Path) -> Path:
    """Upstream's file under our file name, so both parse to the same message (name, topic)."""
    copy = folder / f"{name}.msg"
    copy.write_text(require(SOURCES[name]).read_text(encoding="utf-8"), encoding="utf-8")
    return copy


@pytest.mark.parametrize("name", sorted(SOURCES))
def test_shipped_file_has_upstreams_facts(name: str, tmp_path: Path) -> None:
    ours = uorb.parse_file(SHIPPED / f"{name}.msg").message(f"uorb.{name}")
    theirs = uorb.parse_file(_upstream_as_ours(name, tmp_path)).message(f"uorb.{name}")
    assert ours.uorb is not None and ours.uorb == theirs.uorb  # version, topics, struct size and layout
    assert [f.name for f in ours.fields] == [f.name for f in theirs.fields]
    for mine, upstream in zip(ours.fields, theirs.fields, strict=True):
        assert facts(mine) == facts(upstream), mine.name  # type, unit, range, invalid, enums, frame
    assert facts(ours.constants) == facts(theirs.constants)
    assert facts(ours.enums) == facts(theirs.enums)  # members and kind (bit index, value)
    assert facts(ours) == facts(theirs)  # and nothing else differs but words and places
    assert ours.doc and ours.doc != theirs.doc


def test_the_facts_catch_a_changed_fact(tmp_path: Path) -> None:
    """Not vacuous: one unit changed in upstream's file is a different fact."""
    upstream = _upstream_as_ours("BatteryStatus", tmp_path)
    theirs = uorb.parse_file(upstream).message("uorb.BatteryStatus")
    upstream.write_text(upstream.read_text(encoding="utf-8").replace("# [V] [@invalid 0]", "# [mV] [@invalid 0]"))
    changed = uorb.parse_file(upstream).message("uorb.BatteryStatus")
    assert facts(changed.field("voltage_v")) != facts(theirs.field("voltage_v"))


@pytest.mark.parametrize("name", ["BatteryStatus", "BatteryInfo"])
def test_header_names_the_corpus_commit(name: str) -> None:
    text = (SHIPPED / f"{name}.msg").read_text(encoding="utf-8")
    note = re.search(r"# Facts from PX4-Autopilot (\S+), as px4_msgs main (\w+) ", text)
    assert note is not None
    source = require(CORPUS / "SOURCE.md").read_text(encoding="utf-8")
    main_row = next(line for line in source.splitlines() if line.startswith("| `main/`"))
    assert note.group(2) in main_row and name in note.group(1)


def test_v0_is_the_message_version_0_layout() -> None:
    """BatteryStatusV0 is PX4's MESSAGE_VERSION 0: serial_number, 4 instances."""
    text = (SHIPPED / "BatteryStatusV0.msg").read_text(encoding="utf-8")
    assert "uint32 MESSAGE_VERSION = 0\n" in text and "uint16 serial_number " in text
    assert "uint8 MAX_INSTANCES = 4\n" in text

"""`battgen docs`: Markdown pages per message in the PX4 message reference layout.

The uORB page is checked against PX4's own reference page for BatteryStatusV0
(../shared/seeds/000_*, the seed's copy of PX4's page): the table facts must agree (names, types, units,
ranges, enums, invalid markers, values); the descriptions are our schema's own words, not PX4's.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest
from conftest import ROOT
from shared_data import SHARED, require

from codegen.backends.markdown import (
    INDEX,
    MARKER,
    cell,
    code,
    description,
    page_name,
    range_enum,
    render_docs,
    render_message,
)
from codegen.cli.main import main
from codegen.frontends import uorb
from codegen.frontends.loader import load
from codegen.ir import (
    ArrayType,
    Column,
    Constant,
    EnumDef,
    EnumEntry,
    EnumKind,
    Field,
    Location,
    Message,
    PrimitiveKind,
    PrimitiveType,
    Range,
    Schema,
    Sentinel,
    SourceFormat,
    units,
)

SCHEMAS = ROOT / "schemas"
# PX4's reference page of BatteryStatusV0, read where the seed keeps it (upstream's text is never committed)
PX4_PAGE = SHARED / "seeds" / "000_8cbcba9fe24fb04f.txt"


def _px4_page() -> str:
    return require(PX4_PAGE, "the seed's copy of PX4's BatteryStatusV0 page").read_text(encoding="utf-8")


_PIPE = re.compile(r"(?<!\\)\|")


def cells(row: str) -> list[str]:
    """The cells of a Markdown table row, split on unescaped pipes."""
    return [c.strip() for c in _PIPE.split(row.strip())[1:-1]]


def section(page: str, heading: str) -> str:
    """The text under a heading, up to the next heading of the same or a higher level."""
    level = heading.split(" ", 1)[0]
    start = page.index(heading + "\n") if heading + "\n" in page else page.index(heading + " ")
    rest = page[start + len(heading) :]
    ends = [m.start() for m in re.finditer(f"^#{{1,{len(level)}}} ", rest, re.M)]
    return rest[: ends[0]] if ends else rest


def table(text: str) -> list[list[str]]:
    """Rows of the first table in ``text`` (header and separator dropped)."""
    rows = [line for line in text.splitlines() if line.startswith("|")]
    return [cells(r) for r in rows[2:]]


def tables(text: str) -> dict[str, list[list[str]]]:
    """Each ``### NAME {#NAME}`` heading's table."""
    found = {}
    for match in re.finditer(r"^### (\S+)", text, re.M):
        found[match.group(1)] = table(section(text, f"### {match.group(1)}"))
    return found


@pytest.fixture(scope="module")
def bundled() -> Schema:
    return load([SCHEMAS])


@pytest.fixture(scope="module")
def v0_page() -> str:
    schema = uorb.parse_dir(SCHEMAS / "uorb")
    return render_message(schema, schema.message("uorb.BatteryStatusV0"))


# -- against PX4's reference page ------------------------------------------------------------------


def test_title_doc_and_topics_follow_px4(v0_page: str) -> None:
    px4 = _px4_page()
    assert "# BatteryStatusV0 (UORB message)" in px4
    lines = v0_page.splitlines()
    assert lines[0] == MARKER
    assert "# BatteryStatusV0 (UORB message)" in lines
    assert "**TOPICS:** battery_status_v0" in lines
    assert "State of one battery as the autopilot sees it, in the layout of message version 0" in v0_page
    assert "Battery status information for up to 4 battery instances." in px4  # PX4's words, not ours
    assert "Battery status information for up to 4 battery instances." not in v0_page
    headings = [line for line in lines if line.startswith("## ")]
    assert headings == ["## Fields", "## Enums", "## Constants", "## Source"]


def _invalid(description: str) -> str:
    """The "(Invalid: X)" a description cell ends with, or ""."""
    found = re.search(r"\(Invalid: [^()]*\)$", description)
    return found.group(0) if found else ""


def test_fields_table_matches_px4(v0_page: str) -> None:
    px4_rows = table(section(_px4_page(), "## Fields"))
    ours = table(section(v0_page, "## Fields"))
    assert len(px4_rows) == 39
    # name, type, unit, range/enum, and the "(Invalid: X)" a description ends with: every fact agrees
    assert [row[:4] for row in ours] == [row[:4] for row in px4_rows]
    assert [_invalid(row[4]) for row in ours] == [_invalid(row[4]) for row in px4_rows]
    assert sum(bool(_invalid(row[4])) for row in px4_rows) >= 8
    assert sum(mine[4] != theirs[4] for mine, theirs in zip(ours, px4_rows, strict=True)) > 30  # our words
    by_name = {row[0]: row for row in ours}
    assert by_name["remaining"][3] == "[0 : 1]" and by_name["remaining"][4].endswith("(Invalid: -1)")
    assert by_name["scale"][3] == "[1 : -]"
    assert by_name["temperature"][2] == "°C" and by_name["temperature"][4].endswith("(Invalid: NaN)")
    assert by_name["voltage_cell_v"][1] == "`float32[14]`"
    assert by_name["warning"][3] == "[WARNING](#WARNING)[STATE](#STATE)"


def test_enums_and_constants_match_px4(v0_page: str) -> None:
    px4 = _px4_page()
    px4_enums = tables(section(px4, "## Enums"))
    our_enums = tables(section(v0_page, "## Enums"))
    assert list(our_enums) == list(px4_enums) == ["SOURCE", "WARNING", "STATE", "FAULT"]
    for name, rows in px4_enums.items():
        # PX4 groups constants by prefix, so it lists the FAULT_COUNT counter under FAULT; our IR
        # keeps it out of the bit positions (it is not a fault), and the page shows it as a constant
        expected = [r[:3] for r in rows if r[0] != "FAULT_COUNT"]
        assert [r[:3] for r in our_enums[name]] == expected, name
    px4_constants = table(section(px4, "## Constants"))
    our_constants = table(section(v0_page, "## Constants"))
    assert [r[:3] for r in px4_constants] == [["MESSAGE_VERSION", "`uint32`", "0"], ["MAX_INSTANCES", "`uint8`", "4"]]
    assert [r[:3] for r in our_constants] == [r[:3] for r in px4_constants] + [["FAULT_COUNT", "`uint8`", "11"]]


def test_enum_links_point_at_headings(v0_page: str) -> None:
    for target in re.findall(r"\]\(#([^)]+)\)", v0_page):
        assert f"{{#{target}}}" in v0_page


def test_source_section_names_the_file(v0_page: str) -> None:
    source = section(v0_page, "## Source")
    assert "`BatteryStatusV0.msg`, line 1" in source and "168 bytes" in source


# -- every format ---------------------------------------------------------------------------------


def test_a_page_per_message_and_an_index(bundled: Schema) -> None:
    pages = render_docs(bundled)
    assert set(pages) == {INDEX} | {page_name(m) for m in bundled.messages}
    index = pages[INDEX]
    for msg in bundled.messages:
        assert f"]({page_name(msg)})" in index
        assert pages[page_name(msg)].startswith(f"{MARKER}\n\n# {msg.name} (")
    assert render_docs(bundled) == pages  # deterministic


def test_dronecan_page_has_type_id_signature_and_bit_lengths(bundled: Schema) -> None:
    msg = bundled.message("dronecan.uavcan.equipment.power.BatteryInfo")
    assert msg.dronecan is not None
    page = render_message(bundled, msg)
    assert "# BatteryInfo (DRONECAN message)" in page
    assert "**Data type ID:** 1092" in page
    assert f"`0x{msg.dronecan.signature:016X}`" in page
    assert f"{msg.dronecan.min_bitlen} to {msg.dronecan.max_bitlen}" in page
    assert f"{msg.dronecan.min_bitlen_tao} to {msg.dronecan.max_bitlen_tao}" in page
    rows = {r[0]: r for r in table(section(page, "## Fields"))}
    assert rows["status_flags"][1] == "`uint11`" and rows["status_flags"][3] == "[STATUS_FLAG](#STATUS_FLAG)"
    assert rows["model_name"][1] == "`uint8[<=31]`"
    assert rows["state_of_health_pct"][4].endswith("(Invalid: STATE_OF_HEALTH_UNKNOWN)")
    flags = tables(section(page, "## Enums"))["STATUS_FLAG"]
    assert ["STATUS_FLAG_RESERVED_B", "`uint11`", "1024"] in [r[:3] for r in flags]
    constants = table(section(page, "## Constants"))
    assert [r[:3] for r in constants] == [
        ["STATE_OF_HEALTH_UNKNOWN", "`uint7`", "127"],
        ["STATE_OF_CHARGE_UNKNOWN", "`uint7`", "127"],
    ]
    assert rows["state_of_charge_pct"][4].endswith("(Invalid: STATE_OF_CHARGE_UNKNOWN)")
    aux = render_message(bundled, bundled.message("dronecan.ardupilot.equipment.power.BatteryInfoAux"))
    assert "[`uavcan.Timestamp`](dronecan.uavcan.Timestamp.md)" in aux


def test_mavlink_page_has_id_crc_extra_and_marks_extensions(bundled: Schema) -> None:
    msg = bundled.message("mavlink.BATTERY_STATUS")
    page = render_message(bundled, msg)
    assert "**Message ID:** 147" in page and "**CRC_EXTRA:** 154" in page
    rows = table(section(page, "## Fields"))
    marked = [r[0].removesuffix(" ++") for r in rows if r[0].endswith(" ++")]
    assert marked == [f.name for f in msg.fields if f.extension]
    assert len(marked) == 5
    enums = tables(section(page, "## Enums"))
    assert "MAV_BATTERY_FAULT" in enums  # dialect-level enums used by the message are listed
    assert all(f"[{name}](#{name})" in page for name in enums)


def test_devicetree_page_has_required_patterns_and_additional_properties(bundled: Schema) -> None:
    page = render_message(bundled, bundled.message("devicetree.power.supply.battery"))
    assert "# battery (DEVICETREE binding)" in page
    assert "**Required properties:** `compatible`" in page
    assert "**patternProperties:** `^ocv-capacity-table-[0-9]+$`" in page
    assert "**additionalProperties:** not allowed" in page
    rows = {r[0]: r for r in table(section(page, "## Fields"))}
    assert rows["compatible"][4].startswith("**Required.**")
    assert rows["voltage-min-design-microvolt"][1:3] == ["`int32-matrix`", "microvolt"]
    ocv = rows["`^ocv-capacity-table-[0-9]+$`"]
    assert ocv[3] == "[*][1]: [- : 100]"  # the percent column of every row, from the IR's columns
    assert ocv[4].endswith("<br>`[*][0]`: open-circuit voltage in microvolts <br>`[*][1]`: state of charge in percent")
    span = rows["operating-range-celsius"]
    assert span[3] == "" and "<br>`[1]`: highest usable temperature" in span[4]


def test_column_bounds_and_units_in_cells() -> None:
    loc = Location("t.msg", 1)
    mv = units.lookup("mV")
    cols = (Column("lo | first", range=Range(0, 5, exclusive_minimum=True), unit=mv), Column(), Column("third"))
    t = ArrayType(PrimitiveType(PrimitiveKind.UINT, 16), 4, False, columns=cols)
    f = Field("v", t, loc, range=Range(maximum=9))
    assert range_enum(f) == "[- : 9] [0]: (0 : 5] mV"  # each column on top of the field range
    assert description(f) == "<br>`[0]`: lo \\| first <br>`[2]`: third"


# -- escaping ---------------------------------------------------------------------------------------


def test_schema_text_cannot_break_tables() -> None:
    loc = Location("evil.msg", 1)
    u8 = PrimitiveType(PrimitiveKind.UINT, 8)
    nasty = "a | b\nsecond line <script>x</script> `tick` \\| end"
    enum = EnumDef("test.Evil.MODE", EnumKind.VALUE, (EnumEntry("MODE_A", 0, nasty),))
    msg = Message(
        "Evil",
        "test.Evil",
        SourceFormat.UORB,
        loc,
        "doc",
        (
            Field("x|y", u8, loc, doc=nasty, unit_text="m|s", range=Range(0, 1), invalid=Sentinel(0, "0|1")),
            Field("mode", u8, loc, doc="plain", enums=("test.Evil.MODE",)),
        ),
        constants=(Constant("MODE_A", u8, 0, nasty), Constant("LIMIT", u8, 3, nasty)),
        enums=(enum,),
    )
    page = render_message(Schema(messages=(msg,)), msg)
    for text in (section(page, "## Fields"), section(page, "## Enums"), section(page, "## Constants")):
        rows = [line for line in text.splitlines() if line.startswith("|")]
        assert rows and all(len(cells(r)) == len(cells(rows[0])) for r in rows), rows
    assert "<script>" not in page
    assert "\\|" in page and "<br>" in page


@pytest.mark.parametrize("text", ["plain", "a`b", "``x``", "`", "p|q"])
def test_code_spans_survive_backticks_and_pipes(text: str) -> None:
    span = code(text)
    assert not _PIPE.search(span)
    fence = re.match("`+", span)
    assert fence is not None and fence.group(0) not in span[len(fence.group(0)) : -len(fence.group(0))]


def test_cell_escapes() -> None:
    assert cell("a|b") == "a\\|b"
    assert cell(" one\ntwo \n") == "one<br>two"
    assert cell("x < y & z") == "x &lt; y &amp; z"


# -- the command ------------------------------------------------------------------------------------


def test_docs_command_writes_checks_and_prunes(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    schemas = tmp_path / "schemas"
    shutil.copytree(SCHEMAS / "uorb", schemas / "uorb")
    out = tmp_path / "docs"
    assert main(["docs", str(schemas), "--out", str(out)]) == 0
    written = sorted(p.name for p in out.iterdir())
    assert "index.md" in written and "uorb.BatteryStatusV0.md" in written
    assert main(["docs", str(schemas), "--out", str(out), "--check"]) == 0
    capsys.readouterr()

    page = out / "uorb.BatteryStatusV0.md"
    page.write_text(page.read_text(encoding="utf-8") + "edited\n", encoding="utf-8")
    (out / "uorb.Gone.md").write_text(MARKER + "\n\n# Gone\n", encoding="utf-8")
    (out / "notes.md").write_text("# my own notes\n", encoding="utf-8")
    assert main(["docs", str(schemas), "--out", str(out), "--check"]) == 1
    err = capsys.readouterr().err
    assert f"stale: {page}" in err and "not generated any more" in err and "uorb.Gone.md" in err
    assert "notes.md" not in err

    assert main(["docs", str(schemas), "--out", str(out)]) == 0
    assert not (out / "uorb.Gone.md").exists() and (out / "notes.md").exists()
    assert main(["docs", str(schemas), "--out", str(out), "--check"]) == 0


def test_docs_command_default_output_folder(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["docs", str(SCHEMAS)]) == 0
    assert (tmp_path / "docs" / "messages" / "index.md").is_file()
    capsys.readouterr()

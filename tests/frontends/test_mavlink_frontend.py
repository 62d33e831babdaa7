"""MAVLink XML frontend: error paths (file, line, what was expected) and the IR it builds."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest
from pymavlink.generator import mavparse

from codegen.cli.main import main
from codegen.errors import ErrorList, SchemaError
from codegen.frontends import mavlink
from codegen.ir import ArrayType, EnumKind, PrimitiveKind, PrimitiveType, Range, Schema, Sentinel, StringType

SCHEMAS = Path(__file__).resolve().parents[2] / "schemas" / "mavlink"

HEAD = '<?xml version="1.0"?>\n<mavlink>\n'


def write(tmp_path: Path, name: str, body: str) -> Path:
    path = tmp_path / name
    path.write_text(HEAD + body + "</mavlink>\n", encoding="utf-8")
    return path


def line_of(path: Path, needle: str) -> int:
    lines = path.read_text(encoding="utf-8").splitlines()
    return next(i for i, text in enumerate(lines, 1) if needle in text)


def fails(path: Path, root: Path) -> SchemaError:
    with pytest.raises(SchemaError) as info:
        mavlink.parse_file(path, root=root)
    return info.value


def message(fields: str, *, name: str = "M", msg_id: int = 1) -> str:
    opening = f'<message id="{msg_id}" name="{name}">'
    return f"<messages>\n{opening}\n<description>d</description>\n{fields}</message>\n</messages>\n"


def fld(type_text: str, name: str, extra: str = "") -> str:
    return f'<field type="{type_text}" name="{name}"{extra}>x</field>\n'


def enum(entries: str, *, name: str = "E", extra: str = "") -> str:
    return f'<enums>\n<enum name="{name}"{extra}>\n{entries}</enum>\n</enums>\n'


# ------------------------------------------------------------------------------------------
# Unsafe input never reaches pymavlink's eval()


def test_code_in_enum_value_is_rejected_before_mavparse(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    target = tmp_path / "pwned"
    calls: list[object] = []
    monkeypatch.setattr(mavparse, "MAVXML", lambda *a, **k: calls.append(a))
    evil = f"__import__('os').system('touch {target}')"
    path = write(tmp_path, "evil.xml", enum(f'<entry value="{evil}" name="E_X"/>\n'))
    err = fails(path, tmp_path)
    assert (err.file, err.line) == ("evil.xml", line_of(path, "E_X"))
    assert "integer literal" in err.message and "0x hex" in err.message
    assert not target.exists()
    assert calls == []  # mavparse never saw the file


@pytest.mark.parametrize("value", ["1+1", "0o17", "1_000", " 5", "True", "007", "2**100", "0x", "--1", "1e3", ""])
def test_non_literal_enum_values_are_rejected(tmp_path: Path, value: str) -> None:
    path = write(tmp_path, "v.xml", enum(f'<entry value="{value}" name="E_X"/>\n'))
    err = fails(path, tmp_path)
    assert (err.file, err.line) == ("v.xml", line_of(path, "E_X"))
    assert "expected an integer literal" in err.message


@pytest.mark.parametrize(("value", "expected"), [("0", 0), ("42", 42), ("0x1F", 31), ("0b101", 5), ("2**3", 8),
                                                 ("-1", -1), ("-0x10", -16)])  # fmt: skip
def test_literal_enum_values_match_pymavlink(tmp_path: Path, value: str, expected: int) -> None:
    path = write(tmp_path, "v.xml", enum(f'<entry value="{value}" name="E_X"/>\n'))
    entry = mavlink.parse_file(path, root=tmp_path).enum("mavlink.E").entries[0]
    assert entry.value == expected
    assert mavparse.MAVXML(str(path), mavparse.PROTOCOL_2_0).enum[0].entry[0].value == expected


def test_entry_without_value_counts_on_like_pymavlink(tmp_path: Path) -> None:
    path = write(tmp_path, "v.xml", enum('<entry name="E_A"/>\n<entry value="5" name="E_B"/>\n<entry name="E_C"/>\n'))
    assert [e.value for e in mavlink.parse_file(path).enum("mavlink.E").entries] == [1, 5, 6]


@pytest.mark.parametrize(
    "doctype",
    [
        '<!DOCTYPE mavlink [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">]>',
        '<!DOCTYPE mavlink SYSTEM "file:///etc/passwd">',
        "<!DOCTYPE mavlink>",
    ],
)
def test_doctype_and_entities_are_refused(tmp_path: Path, doctype: str) -> None:
    path = tmp_path / "bomb.xml"
    path.write_text(f'<?xml version="1.0"?>\n{doctype}\n<mavlink><enums/></mavlink>\n', encoding="utf-8")
    err = fails(path, tmp_path)
    assert (err.file, err.line) == ("bomb.xml", 2)
    assert "expected no DOCTYPE" in err.message


def test_text_must_be_utf8(tmp_path: Path) -> None:
    path = tmp_path / "latin.xml"
    path.write_bytes(b'<?xml version="1.0"?>\n<mavlink>\n<!-- caf\xe9 -->\n</mavlink>\n')
    err = fails(path, tmp_path)
    assert (err.file, err.line, err.message) == ("latin.xml", 3, "expected UTF-8 text")


# ------------------------------------------------------------------------------------------
# Malformed documents and attributes


def test_malformed_xml_names_the_line(tmp_path: Path) -> None:
    path = write(tmp_path, "bad.xml", message('<field type="uint8_t" name="a">x</feld>\n'))
    err = fails(path, tmp_path)
    assert (err.file, err.line) == ("bad.xml", line_of(path, "</feld>"))
    assert "expected well-formed XML" in err.message and "mismatched tag" in err.message


def test_wrong_root_element(tmp_path: Path) -> None:
    path = tmp_path / "r.xml"
    path.write_text('<?xml version="1.0"?>\n\n<mavlinks/>\n', encoding="utf-8")
    err = fails(path, tmp_path)
    assert (err.file, err.line) == ("r.xml", 3)
    assert "expected <mavlink> as the root element" in err.message


@pytest.mark.parametrize("type_text", ["uint12_t", "uint8", "float[0]", "char[256]", "string", "int8_t[x]"])
def test_unknown_field_type(tmp_path: Path, type_text: str) -> None:
    path = write(tmp_path, "t.xml", message(fld("uint8_t", "ok") + fld(type_text, "bad")))
    err = fails(path, tmp_path)
    assert (err.file, err.line) == ("t.xml", line_of(path, 'name="bad"'))
    assert "expected a field type int8_t..uint64_t" in err.message and repr(type_text) in err.message


@pytest.mark.parametrize(
    ("field", "expected"),
    [
        ('<field type="uint8_t" name="f" invalid="SOMETIMES">x</field>', "expected invalid= to be a number, NaN"),
        ('<field type="uint8_t" name="f" invalid="NaN">x</field>', "fits uint8"),
        ('<field type="uint8_t" name="f" invalid="UINT16_MAX">x</field>', "fits uint8"),
        ('<field type="int16_t" name="f" invalid="-1.5">x</field>', "fits int16"),
        ('<field type="uint16_t" name="f" invalid="[UINT16_MAX]">x</field>', "only on an array field"),
        ('<field type="uint8_t" name="f" invalid="[1">x</field>', "expected invalid= to be"),
        ('<field type="uint8_t[2]" name="f" invalid="[1,2,3,]">x</field>', "at most 2 positions"),
        ('<field type="uint8_t[2]" name="f" invalid="[,,]">x</field>', "expected invalid= to be"),
        ('<field type="uint8_t[2]" name="f" invalid="[1,x,]">x</field>', "expected invalid= to be"),
        ('<field type="uint8_t[2]" name="f" invalid="[1,256,]">x</field>', "fits uint8"),
        ('<field type="uint8_t" name="f" invalid="[0,]">x</field>', "only on an array field"),
        ('<field type="uint8_t" name="f" minValue="low">x</field>', "expected a number as minValue="),
        ('<field type="uint8_t" name="f" default="x">x</field>', "expected a number as default="),
        ('<field type="uint8_t" name="f" instance="yes">x</field>', 'expected instance="true" or "false"'),
        ('<field type="uint8_t" name="f" enum="NOPE">x</field>', "expected enum NOPE to be defined"),
        ('<field type="uint8_t" name="f[2]">x</field>', "expected an identifier as <field> name"),
        ('<field name="f">x</field>', 'expected a "type" attribute on <field>'),
    ],
)
def test_bad_field_attribute(tmp_path: Path, field: str, expected: str) -> None:
    path = write(tmp_path, "f.xml", message('<field type="uint8_t" name="ok">x</field>\n' + field + "\n"))
    err = fails(path, tmp_path)
    assert (err.file, err.line) == ("f.xml", line_of(path, 'name="f'))
    assert expected in err.message


@pytest.mark.parametrize(
    ("opening", "expected"),
    [
        ('<message name="M">', 'expected a "id" attribute on <message>'),
        ('<message id="0x10" name="M">', "expected a decimal message id"),
        ('<message id="16777216" name="M">', "expected a decimal message id"),
    ],
)
def test_bad_message_attributes(tmp_path: Path, opening: str, expected: str) -> None:
    path = write(tmp_path, "m.xml", f"<messages>\n{opening}\n<description>d</description>\n</message>\n</messages>\n")
    err = fails(path, tmp_path)
    assert (err.file, err.line) == ("m.xml", 4)
    assert expected in err.message


def test_payload_over_255_bytes(tmp_path: Path) -> None:
    path = write(tmp_path, "big.xml", message(fld("uint8_t[255]", "a") + fld("uint8_t", "b")))
    err = fails(path, tmp_path)
    assert (err.file, err.line) == ("big.xml", line_of(path, "<message id"))
    assert "expected at most 255 payload bytes in M, got 256" in err.message


def test_duplicate_field_and_second_extensions_marker(tmp_path: Path) -> None:
    path = write(tmp_path, "d.xml", message(fld("uint8_t", "a") + fld("int8_t", "a")))
    err = fails(path, tmp_path)
    assert (err.line, err.message) == (line_of(path, 'type="int8_t"'), "expected unique field names in M; a repeats")
    path = write(
        tmp_path, "e.xml", message("<extensions/>\n<field type='uint8_t' name='a'>x</field>\n<extensions />\n")
    )
    err = fails(path, tmp_path)
    assert (err.file, err.line) == ("e.xml", line_of(path, "<extensions />"))
    assert "at most one <extensions/>" in err.message


def test_duplicate_enum_value(tmp_path: Path) -> None:
    path = write(tmp_path, "e.xml", enum('<entry value="1" name="E_A"/>\n<entry value="1" name="E_B"/>\n'))
    err = fails(path, tmp_path)
    assert (err.file, err.line) == ("e.xml", line_of(path, "E_B"))
    assert "expected unique entry names and values in enum E" in err.message and "E_A" in err.message


# ------------------------------------------------------------------------------------------
# Includes


def test_missing_include(tmp_path: Path) -> None:
    path = write(tmp_path, "top.xml", "<include>nope.xml</include>\n")
    err = fails(path, tmp_path)
    assert (err.file, err.line) == ("top.xml", 3)
    assert "expected nope.xml to exist relative to this file" in err.message


def test_include_cycle(tmp_path: Path) -> None:
    write(tmp_path, "a.xml", "<include>sub/b.xml</include>\n")
    (tmp_path / "sub").mkdir()
    b = write(tmp_path / "sub", "b.xml", "\n<include>../a.xml</include>\n")
    err = fails(tmp_path / "a.xml", tmp_path)
    assert (err.file, err.line) == ("sub/b.xml", line_of(b, "../a.xml"))
    assert "closes an include cycle" in err.message


def test_self_include_is_a_cycle(tmp_path: Path) -> None:
    path = write(tmp_path, "s.xml", "<include>s.xml</include>\n")
    err = fails(path, tmp_path)
    assert (err.file, err.line) == ("s.xml", 3) and "include cycle" in err.message


def test_includes_resolve_relative_and_once(tmp_path: Path) -> None:
    (tmp_path / "lib").mkdir()
    write(tmp_path / "lib", "base.xml", enum('<entry value="0" name="E_A"/>\n') + message("", name="BASE", msg_id=1))
    write(tmp_path / "lib", "mid.xml", "<include>base.xml</include>\n" + message("", name="MID", msg_id=2))
    includes = "<include>lib/mid.xml</include>\n<include>lib/base.xml</include>\n"
    body = enum('<entry value="7" name="E_B"/>\n') + message(fld("uint8_t", "f", ' enum="E"'), name="TOP", msg_id=3)
    top = write(tmp_path, "top.xml", includes + body)
    schema = mavlink.parse_file(top, root=tmp_path)
    assert schema.sources == ("lib/base.xml", "lib/mid.xml", "top.xml")
    assert [(m.name, m.mavlink.dialect if m.mavlink else None, m.location.file) for m in schema.messages] == [
        ("BASE", "base", "lib/base.xml"), ("MID", "mid", "lib/mid.xml"), ("TOP", "top", "top.xml")
    ]  # fmt: skip
    merged = schema.enum("mavlink.E")  # extended by the includer: merged, located at its first definition
    assert [(e.name, e.value, e.location.file if e.location else "") for e in merged.entries] == [
        ("E_A", 0, "lib/base.xml"), ("E_B", 7, "top.xml")
    ]  # fmt: skip
    assert merged.location is not None and merged.location.file == "lib/base.xml"
    # parse_dir reads every file once, so shared includes do not clash with themselves
    assert mavlink.parse_dir(tmp_path).messages == schema.messages


def test_duplicate_message_id_across_files(tmp_path: Path) -> None:
    write(tmp_path, "a.xml", message("", name="A", msg_id=9))
    path = write(tmp_path, "b.xml", "<include>a.xml</include>\n" + message("", name="B", msg_id=9))
    err = fails(path, tmp_path)
    assert (err.file, err.line) == ("b.xml", line_of(path, "<message id"))
    assert "expected unique message names and ids; B (id 9) clashes with A at a.xml:" in err.message


# ------------------------------------------------------------------------------------------
# pymavlink's own failures are contained


def test_mavparse_exit_and_output_become_schema_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    def exits(*_: object) -> None:
        print("noise from mavparse")
        raise SystemExit(1)

    monkeypatch.setattr(mavparse, "MAVXML", exits)
    path = write(tmp_path, "x.xml", message(""))
    err = fails(path, tmp_path)
    assert (err.file, err.line) == ("x.xml", 1) and "expected a dialect pymavlink accepts (SystemExit" in err.message
    assert capsys.readouterr().out == ""

    def raises(filename: str, *_: object) -> None:
        raise mavparse.MAVParseError(f"something odd at {filename}:4")

    monkeypatch.setattr(mavparse, "MAVXML", raises)
    err = fails(path, tmp_path)
    assert (err.file, err.line) == ("x.xml", 4) and err.message.endswith("something odd at x.xml:4)")


def test_unreadable_file(tmp_path: Path) -> None:
    err = fails(tmp_path / "absent.xml", tmp_path)
    assert err.file == "absent.xml" and "cannot read file" in err.message


# ------------------------------------------------------------------------------------------
# IR mapping


def test_field_mapping_details(tmp_path: Path) -> None:
    fields = """\
<field type="char[16]" name="label">x</field>
<field type="char" name="letter">x</field>
<field type="uint8_t_mavlink_version" name="version">x</field>
<field type="float[4]" name="q" invalid="[NaN:]">x</field>
<field type="uint8_t" name="state" enum="E" invalid="E_UNKNOWN">x</field>
<field type="uint16_t" name="flags" enum="F" display="bitmask" print_format="0x%04x">x</field>
<field type="uint8_t" name="cam" default="0" minValue="0" maxValue="6" multiplier="1E-2" increment="1">x</field>
<field type="int16_t" name="neg" invalid="-1.0" units="m/s*5">x</field>
<field type="double" name="d" invalid="NAN">x</field>
"""
    enums = enum('<entry value="0" name="E_UNKNOWN"/>\n<entry value="1" name="E_OK"/>\n') + enum(
        '<entry value="1" name="F_A"/>\n<entry value="4" name="F_B"/>\n', name="F"
    )
    path = write(tmp_path, "x.xml", "<version>3</version>\n" + enums + message(fields))
    schema = mavlink.parse_file(path, root=tmp_path)
    m = schema.message("mavlink.M")
    assert m.field("label").type == StringType(capacity=16)
    assert m.field("letter").type == PrimitiveType(PrimitiveKind.CHAR, 8)
    version = m.field("version")
    assert (version.type, version.const) == (PrimitiveType(PrimitiveKind.UINT, 8), 3)
    assert ("type", "uint8_t_mavlink_version") in version.annotations
    q = m.field("q")
    assert q.type == ArrayType(PrimitiveType(PrimitiveKind.FLOAT, 32), 4, dynamic=False)
    assert q.invalid is not None and q.invalid.is_nan
    # [X:]: the first element decides for the whole array; it marks no element by itself
    assert (q.invalid.text, q.invalid.per_element, q.invalid.first_decides) == ("[NaN:]", False, True)
    assert m.field("state").invalid == Sentinel(0, "E_UNKNOWN")
    assert m.field("flags").annotations == (("display", "bitmask"), ("print_format", "0x%04x"))
    cam = m.field("cam")
    assert (cam.range, cam.default) == (Range(0, 6), 0)
    assert cam.annotations == (("multiplier", "1E-2"), ("increment", "1"))
    neg = m.field("neg")
    assert neg.invalid == Sentinel(-1, "-1.0") and isinstance(neg.invalid.value, int)
    assert neg.unit is not None and (neg.unit_text, neg.unit.quantity) == ("m/s*5", "unknown:m/s*5")
    d = m.field("d").invalid
    assert d is not None and math.isnan(d.value)
    # F has no bitmask attribute but powers of two and a display="bitmask" field; E is plain
    assert schema.enum("mavlink.F").kind is EnumKind.BITMASK
    assert schema.enum("mavlink.E").kind is EnumKind.VALUE


def test_deprecation_and_wip_notes_end_the_doc(tmp_path: Path) -> None:
    entries = """\
<entry value="0" name="E_OLD"><deprecated since="2020-01" replaced_by="E_NEW">Gone.</deprecated><description>Old one.</description></entry>
<entry value="1" name="E_NEW"><wip/><description>New one.</description></entry>
<entry value="2" name="E_SUP"><superseded since="2024-02" replaced_by=""/><description>Replaced.</description></entry>
"""  # noqa: E501
    path = write(tmp_path, "x.xml", enum(entries))
    docs = [e.doc for e in mavlink.parse_file(path).enum("mavlink.E").entries]
    assert docs == [
        "Old one. [deprecated since 2020-01; replaced by E_NEW: Gone.]",
        "New one. [work in progress]",
        "Replaced. [superseded since 2024-02]",
    ]


# ------------------------------------------------------------------------------------------
# Our shipped battery dialect


@pytest.fixture(scope="module")
def battery_schema() -> Schema:
    return mavlink.parse_file(SCHEMAS / "battery.xml", root=SCHEMAS)  # vehicle.xml has its own test


def test_battery_status_message(battery_schema: Schema) -> None:
    msg = battery_schema.message("mavlink.BATTERY_STATUS")
    assert battery_schema.sources == ("battery.xml",)
    assert (msg.name, msg.location.file) == ("BATTERY_STATUS", "battery.xml")
    assert msg.location.line == line_of(SCHEMAS / "battery.xml", '<message id="147"')
    assert msg.doc.startswith("A battery as the flight controller monitors it: cell voltages, current,")
    info = msg.mavlink
    assert info is not None
    assert (info.msg_id, info.crc_extra, info.dialect, info.base_length, info.max_length) == (
        147,
        154,
        "battery",
        36,
        54,
    )
    assert info.wire_order[:5] == ("current_consumed", "energy_consumed", "temperature", "voltages", "current_battery")
    assert info.wire_order[-5:] == ("time_remaining", "charge_state", "voltages_ext", "mode", "fault_bitmask")
    assert [f.name for f in msg.fields if f.extension] == list(info.wire_order[-5:])
    assert msg.field("id").annotations == (("instance", "true"),)


def test_battery_status_units_and_sentinels(battery_schema: Schema) -> None:
    msg = battery_schema.message("mavlink.BATTERY_STATUS")
    units = {f.name: (f.unit_text, f.unit.symbol, f.unit.quantity) for f in msg.fields if f.unit is not None}
    assert units == {
        "temperature": ("cdegC", "cdegC", "temperature"),
        "voltages": ("mV", "mV", "voltage"),
        "current_battery": ("cA", "cA", "current"),
        "current_consumed": ("mAh", "mAh", "charge"),
        "energy_consumed": ("hJ", "hJ", "energy"),
        "battery_remaining": ("%", "%", "ratio"),
        "time_remaining": ("s", "s", "time"),
        "voltages_ext": ("mV", "mV", "voltage"),
    }
    assert msg.field("temperature").invalid == Sentinel(32767, "INT16_MAX")
    voltages = msg.field("voltages")
    assert voltages.type == ArrayType(PrimitiveType(PrimitiveKind.UINT, 16), 10, dynamic=False)
    assert voltages.invalid == Sentinel(65535, "[UINT16_MAX]", per_element=True)
    for name in ("current_battery", "current_consumed", "energy_consumed", "battery_remaining"):
        assert msg.field(name).invalid == Sentinel(-1, "-1"), name
    assert msg.field("time_remaining").invalid == Sentinel(0, "0")  # upstream's markers since 2021
    assert msg.field("voltages_ext").invalid == Sentinel(0, "[0]", per_element=True)


def test_battery_status_enums(battery_schema: Schema) -> None:
    msg = battery_schema.message("mavlink.BATTERY_STATUS")
    refs = {f.name: f.enums for f in msg.fields if f.enums}
    assert refs == {
        "battery_function": ("mavlink.MAV_BATTERY_FUNCTION",),
        "type": ("mavlink.MAV_BATTERY_TYPE",),
        "charge_state": ("mavlink.MAV_BATTERY_CHARGE_STATE",),
        "mode": ("mavlink.MAV_BATTERY_MODE",),
        "fault_bitmask": ("mavlink.MAV_BATTERY_FAULT",),
    }
    others = ("mavlink.MAV_BATTERY_STATUS_FLAGS",)  # BATTERY_STATUS_V2's
    assert [e.name for e in battery_schema.enums] == sorted([n for (n,) in refs.values()] + list(others))
    fault = battery_schema.enum("mavlink.MAV_BATTERY_FAULT")
    assert fault.kind is EnumKind.BITMASK
    assert [e.value for e in fault.entries] == [1 << i for i in range(9)]
    assert fault.entries[-1].name == "BATTERY_FAULT_INCOMPATIBLE_CELLS_CONFIGURATION"
    state = battery_schema.enum("mavlink.MAV_BATTERY_CHARGE_STATE")
    assert state.kind is EnumKind.VALUE and len(state.entries) == 8
    assert state.entries[5].name == "MAV_BATTERY_CHARGE_STATE_FAILED" and state.entries[5].value == 5
    assert all(
        e.doc and e.location and e.location.file == "battery.xml" for en in battery_schema.enums for e in en.entries
    )


@pytest.mark.parametrize(
    ("attr", "value", "elements"),
    [
        # the array forms of the MAVLink guide's invalid attribute; [0,] is development.xml's CONTROL_STATUS
        ("[0,]", 0, (0,)),
        ("[7,,UINT8_MAX,]", 7, (7, None, 255)),
        ("[,5]", 5, (None, 5)),
        ("[3]", 3, ()),
        ("[3:]", 3, ()),
    ],
)
def test_array_invalid_forms(tmp_path: Path, attr: str, value: int, elements: tuple[int | None, ...]) -> None:
    path = write(tmp_path, "a.xml", message(fld("uint8_t[4]", "a", f' invalid="{attr}"')))
    s = mavlink.parse_file(path, root=tmp_path).message("mavlink.M").field("a").invalid
    first = attr.endswith(":]")  # [X:]: the first element decides for the whole array
    assert s == Sentinel(value, attr, per_element=not first, elements=elements, first_decides=first)
    expected = list(elements) + [None] * (4 - len(elements)) if elements else [value] * 4
    assert s is not None and [s.marker_at(i) for i in range(4)] == expected


def test_positional_invalid_in_generated_code(tmp_path: Path, import_generated: Any) -> None:
    """Marked positions default to their marker; an element without a marker is always known."""
    fields = fld("int16_t[3]", "a", ' invalid="[-5,,7,]"') + fld("int16_t[2]", "b", ' invalid="[-5,7,]"')
    path = write(tmp_path, "p.xml", message(fields))
    m = import_generated(mavlink.parse_file(path, root=tmp_path), "mavlink").M()
    assert (m.a, m.b) == ([-5, 0, 7], [-5, 7])
    assert m.is_known("a") and not m.is_known("b")
    m.b = [-5, 8]
    assert m.is_known("b")


# ------------------------------------------------------------------------------------------
# A folder reports every bad file in one run


def test_a_folder_reports_every_bad_file_at_once(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Bad files do not hide each other: a missing include, a file pymavlink rejects, a bad invalid=, a bad
    message beside a good one (which still builds, and clashes with a later file) all come in one report;
    a bad file read twice (c_uses_broken.xml includes it) is reported once."""
    folder = tmp_path / "mavlink"  # a schema folder's MAVLink part, so the command line reads it too
    folder.mkdir()
    write(folder, "a_missing.xml", "<include>nowhere.xml</include>\n" + message(fld("uint8_t", "x"), msg_id=1))
    write(folder, "b_broken.xml", message(fld("uint8_t", "x") + "<field>", name="B", msg_id=2))
    write(folder, "c_uses_broken.xml", "<include>b_broken.xml</include>\n" + message(fld("uint8_t", "x"), name="C"))
    write(folder, "d_invalid.xml", message(fld("uint8_t", "x", ' invalid="[300]"'), name="D", msg_id=4))
    bad_first = message(fld("uint8_t", "x", ' invalid="UNKNOWN_NAME"'), name="E", msg_id=5)
    write(folder, "e_two.xml", bad_first.replace("</messages>", "") + message(fld("uint8_t", "y"), name="F", msg_id=7)
          .replace("<messages>\n", ""))  # fmt: skip
    write(folder, "f_clash.xml", message(fld("uint8_t", "x"), name="F", msg_id=8))
    with pytest.raises(ErrorList) as caught:
        mavlink.parse_dir(folder)
    lines = [str(e) for e in caught.value.errors]
    files = [line.split(":", 1)[0] for line in lines]
    assert files.count("b_broken.xml") == 1  # read once, though c_uses_broken.xml includes it
    assert {"a_missing.xml", "b_broken.xml", "d_invalid.xml", "e_two.xml", "f_clash.xml"} == set(files), lines
    assert any("nowhere.xml" in line for line in lines)
    assert any(line.startswith("e_two.xml") and "UNKNOWN_NAME" in line for line in lines)
    assert any(line.startswith("f_clash.xml") and "clashes with F at e_two.xml" in line for line in lines)
    assert len(lines) == 5, lines
    assert str(caught.value).endswith(f"{len(lines)} errors")
    # the command line prints them all and exits 2
    assert main(["list", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert all(line.split(": ", 1)[1][:50] in err for line in lines), err

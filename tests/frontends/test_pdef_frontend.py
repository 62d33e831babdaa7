"""The ArduPilot parameter metadata frontend (apm.pdef.xml layout): IR facts and error paths."""

from __future__ import annotations

from pathlib import Path

import pytest

from codegen.errors import SchemaError
from codegen.frontends import pdef
from codegen.frontends.loader import format_of_file, load
from codegen.ir import EnumKind, PrimitiveKind, Range, SourceFormat
from codegen.ir import json_form as irjson

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = ROOT / "schemas" / "params" / "battery_failsafe.pdef.xml"


def write(tmp_path: Path, body: str, name: str = "x.pdef.xml") -> Path:
    path = tmp_path / name
    path.write_text('<?xml version="1.0" encoding="utf-8"?>\n' + body, encoding="utf-8")
    return path


def group(params_xml: str, name: str = "BATT_") -> str:
    return f'<paramfile><libraries><parameters name="{name}">\n{params_xml}\n</parameters></libraries></paramfile>\n'


def error(tmp_path: Path, body: str) -> SchemaError:
    with pytest.raises(SchemaError) as info:
        pdef.parse_file(write(tmp_path, body), root=tmp_path)
    assert info.value.file == "x.pdef.xml"
    return info.value


def test_shipped_schema_facts() -> None:
    schema = pdef.parse_dir(ROOT / "schemas" / "params")
    msg = schema.message("params.BATT")
    assert (msg.name, msg.format, msg.params and msg.params.prefix) == ("BATT", SourceFormat.PDEF, "BATT_")
    names = [f.name for f in msg.fields]
    for expected in ("BATT_LOW_VOLT", "BATT_CRT_VOLT", "BATT_LOW_MAH", "BATT_CRT_MAH", "BATT_FS_LOW_ACT"):
        assert expected in names
    low = msg.field("BATT_LOW_VOLT")
    assert low.unit is not None and (low.unit.symbol, low.unit.quantity) == ("V", "voltage")
    # AP_BattMonitor_Params.cpp declares no @Range for the voltages (a 12S pack is 50 V)
    assert (low.range, low.default, low.type.name) == (None, 0.0, "float32")  # type: ignore[union-attr]
    assert ("Increment", "0.1") in low.annotations and ("humanName", "Low battery voltage") in low.annotations
    timer = msg.field("BATT_LOW_TIMER")
    assert (timer.default, timer.unit and timer.unit.symbol, timer.range) == (10, "s", Range(0, 120))
    cap = msg.field("BATT_CAPACITY")
    assert cap.unit is not None and cap.unit.symbol == "mAh" and cap.type.name == "int32"  # type: ignore[union-attr]
    # the action codes mean something else per vehicle (@Values{Rover}, {Copter}...): no enum here
    assert msg.field("BATT_FS_LOW_ACT").enums == () and msg.field("BATT_FS_LOW_ACT").type.name == "int8"  # type: ignore[union-attr]
    src = schema.enum("params.BATT.FS_VOLTSRC")
    assert [e.value for e in src.entries] == [0, 1]
    assert irjson.validate_ir_json(irjson.schema_to_json(schema)) == []


def test_loader_tells_pdef_from_mavlink_xml() -> None:
    assert format_of_file(Path("apm.pdef.xml")) == "params"
    assert format_of_file(Path("common.xml")) == "mavlink"
    assert [m.qualified_name for m in load([SHIPPED]).messages] == ["params.BATT"]


def test_generated_model() -> None:
    from generated.params import BattParams

    p = BattParams.from_dict({"BATT_LOW_VOLT": 10.5, "BATT_FS_LOW_ACT": 2})
    assert (p.BATT_LOW_VOLT, p.BATT_FS_LOW_ACT, p.BATT_LOW_TIMER) == (10.5, 2, 10)
    assert BattParams.QUALIFIED_NAME == "params.BATT"


def test_real_pdef_forms_values_bitmask_inference_vehicle(tmp_path: Path) -> None:
    body = """<paramfile>
  <vehicles>
    <parameters name="ArduCopter">
      <param humanName="Frame" name="ArduCopter:FRAME_CLASS" documentation="Frame class" user="Standard">
        <values><value code="0">Undefined</value><value code="1">Quad</value></values>
      </param>
    </parameters>
  </vehicles>
  <libraries>
    <parameters name="BATT_">
      <param name="BATT_OPTIONS" documentation="Options">
        <field name="Bitmask">0:Ignore UAVCAN SoC,1:MPPT reports input voltage</field>
      </param>
      <param name="BATT_SERIAL_NUM">
        <field name="Range">-1 100</field><field name="Increment">1</field>
      </param>
      <param name="BATT_VOLT_MULT"><field name="Range">0 100</field><field name="UnitText">ratio</field></param>
      <param name="BATT_ODD"><field name="Units">furlong</field><field name="Values">0:Off,1:On</field></param>
    </parameters>
  </libraries>
</paramfile>"""
    schema = pdef.parse_file(write(tmp_path, body), root=tmp_path)
    assert [m.qualified_name for m in schema.messages] == ["params.ArduCopter", "params.BATT"]
    copter = schema.message("params.ArduCopter")
    assert copter.fields[0].name == "FRAME_CLASS" and copter.params is not None and copter.params.section == "vehicles"
    batt = schema.message("params.BATT")
    options = schema.enum("params.BATT.OPTIONS")
    assert options.kind is EnumKind.BITMASK and [e.value for e in options.entries] == [1, 2]
    assert batt.field("BATT_OPTIONS").type.name == "int8"  # type: ignore[union-attr]
    serial = batt.field("BATT_SERIAL_NUM").type
    assert serial.kind is PrimitiveKind.INT and serial.bits == 8  # type: ignore[union-attr]
    assert batt.field("BATT_VOLT_MULT").type.name == "float32"  # type: ignore[union-attr]
    odd = batt.field("BATT_ODD")
    assert odd.unit_text == "furlong" and odd.unit is not None and odd.enums == ("params.BATT.ODD",)


@pytest.mark.parametrize(
    ("body", "line", "expected"),
    [
        ("<mavlink/>", 2, "expected <paramfile> as the root element"),
        (group('<param name="BATT_X"><field name="Range">0</field></param>'), 3, "expected Range as two numbers"),
        (group('<param name="BATT_X"><field name="Range">5 1</field></param>'), 3, "expected Range min <= max"),
        (group('<param name="BATT_X"><field name="Type">double</field></param>'), 3, "expected Type float, int8"),
        (
            group('<param name="BATT_X"><field name="Type">int8</field><field name="Range">0 300</field></param>'),
            3,
            "expected a Range within int8",
        ),
        (
            group('<param name="BATT_X">\n<field name="Range">0 30</field>\n<field name="Default">31</field></param>'),
            5,
            "expected a Default within Range",
        ),
        (
            group('<param name="BATT_X"><field name="Type">int8</field><field name="Default">1.5</field></param>'),
            3,
            "expected an integer Default",
        ),
        (group('<param name="BATT_X">\n<values><value code="a">A</value></values></param>'), 4, "integer code"),
        (
            group(
                '<param name="BATT_X"><values>\n<value code="1">A</value>\n<value code="1">B</value></values></param>'
            ),
            5,
            "expected each code once",
        ),
        (group('<param name="BATT_X"><field name="Values">0:A,B</field></param>'), 3, "code:label pairs"),
        (group('<param name="BATT_A"/>\n<param name="BATT_A"/>'), 4, "expected each parameter once"),
        (group('<param name="BATT_THIS_NAME_IS_TOO_LONG"/>'), 3, "1 to 16 letters"),
        (group("<param/>"), 3, 'expected a "name" attribute on <param>'),
        (group('<param name="BATT_X"><foo/></param>'), 3, "expected <field>, <values> or <bitmask>"),
        (
            group('<param name="BATT_X"><field name="Type">int8</field><field name="Bitmask">9:High</field></param>'),
            3,
            "expected a bit number from 0 to 7",
        ),
        ("<paramfile><libraries>\n<parameters/></libraries></paramfile>", 3, 'expected a "name" attribute'),
        ("<paramfile>\n<other/></paramfile>", 3, "expected <vehicles> or <libraries>"),
        ("<paramfile>\n<libraries>\n</paramfile>", 4, "expected well-formed XML"),
        ('<!DOCTYPE p [<!ENTITY x "y">]>\n<paramfile/>', 2, "expected no DOCTYPE"),
    ],
)
def test_errors_name_file_line_and_expectation(tmp_path: Path, body: str, line: int, expected: str) -> None:
    exc = error(tmp_path, body)
    assert exc.line == line, exc
    assert expected in exc.message


@pytest.mark.parametrize(
    "doctype",
    ['<!DOCTYPE paramfile SYSTEM "file:///etc/passwd">', "<!DOCTYPE paramfile>"],
)
def test_any_doctype_is_refused(tmp_path: Path, doctype: str) -> None:
    exc = error(tmp_path, f"{doctype}\n<paramfile/>")
    assert exc.line == 2
    assert exc.message == "expected no DOCTYPE (apm.pdef.xml needs no DTD)"


def test_text_must_be_utf8(tmp_path: Path) -> None:
    path = tmp_path / "x.pdef.xml"
    path.write_bytes(b'<?xml version="1.0"?>\n<paramfile>\n<!-- caf\xe9 -->\n</paramfile>\n')
    with pytest.raises(SchemaError) as info:
        pdef.parse_file(path, root=tmp_path)
    assert (info.value.file, info.value.line, info.value.message) == ("x.pdef.xml", 3, "expected UTF-8 text")


def test_unreadable_and_duplicate_groups(tmp_path: Path) -> None:
    with pytest.raises(SchemaError, match="cannot read file"):
        pdef.parse_file(tmp_path / "missing.pdef.xml")
    (tmp_path / "a.pdef.xml").write_text(group('<param name="BATT_A"/>'), encoding="utf-8")
    (tmp_path / "b.pdef.xml").write_text(group('<param name="BATT_B"/>'), encoding="utf-8")
    with pytest.raises(SchemaError) as info:
        pdef.parse_dir(tmp_path)
    assert (info.value.file, info.value.line) == ("b.pdef.xml", 1)
    assert "expected one definition of params.BATT" in info.value.message

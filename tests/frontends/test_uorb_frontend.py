"""The PX4 uORB .msg frontend: syntax, comment metadata, enums, topics, layout and errors."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from schema_facts import facts
from shared_data import missing, shared

from codegen.errors import SchemaError
from codegen.frontends import uorb
from codegen.frontends.uorb.build import snake_case
from codegen.ir import (
    ArrayType,
    CompositeType,
    EnumKind,
    Message,
    PrimitiveKind,
    PrimitiveType,
    Range,
    Sentinel,
    StringType,
)

SCHEMAS = Path(__file__).resolve().parents[2] / "schemas" / "uorb"
HEAD = "uint64 timestamp # [us] Time since system start\n"


def write(directory: Path, name: str, body: str) -> Path:
    path = directory / f"{name}.msg"
    path.write_text(body, encoding="utf-8")
    return path


def parse(directory: Path, body: str, name: str = "Sample") -> Message:
    path = write(directory, name, body)
    return uorb.parse_file(path, root=directory).message(f"uorb.{name}")


def error(directory: Path, body: str, name: str = "Sample") -> SchemaError:
    path = write(directory, name, body)
    with pytest.raises(SchemaError) as info:
        uorb.parse_file(path, root=directory)
    return info.value


@pytest.fixture(scope="module")
def battery() -> tuple[Message, Message]:
    schema = uorb.parse_dir(SCHEMAS)
    return schema.message("uorb.BatteryStatus"), schema.message("uorb.BatteryStatusV0")


# ---------------------------------------------------------------------------------------------
# the shipped battery messages


def test_battery_messages_are_named_and_located(battery: tuple[Message, Message]) -> None:
    v1, v0 = battery
    assert (v1.name, v1.qualified_name, v1.location.file) == (
        "BatteryStatus",
        "uorb.BatteryStatus",
        "BatteryStatus.msg",
    )
    assert (v0.name, v0.qualified_name, v0.location.file) == (
        "BatteryStatusV0",
        "uorb.BatteryStatusV0",
        "BatteryStatusV0.msg",
    )
    assert uorb.parse_dir(SCHEMAS) == uorb.parse_dir(SCHEMAS)  # deterministic


def test_v0_file_has_the_seed_sources_facts(tmp_path: Path) -> None:
    """The seed quotes PX4's BatteryStatusV0.msg; ours holds its facts (names, types, units, ...) in our words."""
    seeds = sorted(shared("seeds").glob("000_*.txt"))
    if not seeds:
        missing("the seed holding PX4's original BatteryStatusV0.msg")
    seed = seeds[0].read_text(encoding="utf-8")
    block = seed[seed.index("## Source Message") :]
    start = block.index("```c\n") + len("```c\n")
    original = block[start : block.index("\n```", start)] + "\n"
    assert "# TOPICS" not in original
    (tmp_path / "BatteryStatusV0.msg").write_text(original, encoding="utf-8")
    theirs = uorb.parse_file(tmp_path / "BatteryStatusV0.msg").message("uorb.BatteryStatusV0")
    ours = uorb.parse_file(SCHEMAS / "BatteryStatusV0.msg").message("uorb.BatteryStatusV0")
    assert facts(ours) == facts(theirs) and ours.doc != theirs.doc


def test_version_topics_and_doc(battery: tuple[Message, Message]) -> None:
    v1, v0 = battery
    assert v1.uorb is not None and v0.uorb is not None
    assert (v1.uorb.message_version, v0.uorb.message_version) == (1, 0)
    assert (v1.uorb.topics, v0.uorb.topics) == (("battery_status",), ("battery_status_v0",))
    assert v0.doc.splitlines()[0].startswith("State of one battery as the autopilot sees it, in the layout of")
    assert v1.doc.splitlines()[0].startswith("State of one battery as the autopilot sees it, one instance per pack")
    assert not any("Facts from" in line for line in v0.doc.splitlines() + v1.doc.splitlines())  # the header
    assert not any("MESSAGE_VERSION" in line for line in v0.doc.splitlines())


def test_v1_differs_from_v0_as_specified(battery: tuple[Message, Message]) -> None:
    v1, v0 = battery
    names1, names0 = [f.name for f in v1.fields], [f.name for f in v0.fields]
    assert [n for n in names0 if n != "serial_number"] == names1 and "serial_number" in names0
    consts1 = {c.name: c.value for c in v1.constants}
    consts0 = {c.name: c.value for c in v0.constants}
    assert (consts1["MAX_INSTANCES"], consts0["MAX_INSTANCES"]) == (3, 4)
    # PX4 main names 6 and 7 as V0 does, under [@enum WARNING STATE]
    assert (consts1["STATE_UNHEALTHY"], consts1["STATE_CHARGING"]) == (6, 7) and "WARNING_UNHEALTHY" not in consts1
    assert (consts0["STATE_UNHEALTHY"], consts0["STATE_CHARGING"]) == (6, 7)
    t1, t0 = v1.field("temperature"), v0.field("temperature")
    assert (t1.unit_text, t0.unit_text) == ("degC", "°C")
    assert t1.unit == t0.unit and t1.unit is not None and t1.unit.symbol == "degC"
    assert v1.field("warning").enums == ("uorb.BatteryStatus.WARNING", "uorb.BatteryStatus.STATE")
    assert (v1.field("remaining_capacity_wh").invalid, v0.field("remaining_capacity_wh").invalid) == (
        Sentinel(math.nan, "NaN"),
        None,
    )
    assert v1.field("nominal_voltage").invalid == Sentinel(math.nan, "NaN")
    assert (v1.field("scale").unit_text, v0.field("scale").unit_text) == ("-", None)
    assert v0.field("warning").enums == ("uorb.BatteryStatusV0.WARNING", "uorb.BatteryStatusV0.STATE")


def test_battery_annotations(battery: tuple[Message, Message]) -> None:
    _, v0 = battery
    assert v0.field("remaining").range == Range(0, 1)
    assert v0.field("scale").range == Range(1, None)  # [@range 1,]: open maximum
    assert v0.field("state_of_health").range == Range(0, 100)  # [@range 0, 100]: spaces allowed
    assert v0.field("current_a").invalid == Sentinel(-1.0, "-1")
    nan = v0.field("time_remaining_s").invalid
    assert nan is not None and nan.is_nan and nan.text == "NaN" and not nan.per_element
    cells = v0.field("voltage_cell_v")
    assert cells.type == ArrayType(PrimitiveType(PrimitiveKind.FLOAT, 32), 14, dynamic=False)
    assert cells.invalid == Sentinel(0.0, "0", per_element=True) and cells.unit_text == "V"
    minutes = v0.field("average_time_to_empty").unit
    assert minutes is not None and minutes.symbol == "min"
    assert v0.field("internal_resistance_estimate").unit_text == "Ohm"
    assert v0.field("voltage_v").doc == "Pack voltage"
    assert v0.field("connected").unit is None and v0.field("connected").invalid is None


def test_battery_enums(battery: tuple[Message, Message]) -> None:
    v1, v0 = battery
    assert [e.name for e in v0.enums] == [f"uorb.BatteryStatusV0.{g}" for g in ("SOURCE", "WARNING", "STATE", "FAULT")]
    warning, state = v0.enums[1], v0.enums[2]
    assert warning.kind is EnumKind.VALUE and [e.value for e in warning.entries] == [0, 1, 2, 3, 4]
    assert state.kind is EnumKind.VALUE and [e.name for e in state.entries] == ["STATE_UNHEALTHY", "STATE_CHARGING"]
    fault = v0.enums[3]
    assert fault.kind is EnumKind.BIT_INDEX
    assert [e.value for e in fault.entries] == list(range(11)) and "FAULT_COUNT" not in [e.name for e in fault.entries]
    assert any(c.name == "FAULT_COUNT" and c.value == 11 for c in v0.constants)  # kept as a constant
    assert fault.entries[2].name == "FAULT_CELL_FAIL"  # written "FAULT_CELL_FAIL= 2"
    assert fault.entries[0].doc == "Discharged too deep" and fault.entries[0].location is not None
    assert [e.name for e in v1.enums] == [e.name.replace("StatusV0", "Status") for e in v0.enums]
    assert [e.value for e in v1.enums[1].entries] == [0, 1, 2, 3, 4]
    assert [e.value for e in v1.enums[2].entries] == [6, 7]
    assert len(v0.constants) == 2 + 3 + 7 + 12  # every constant stays, enum members included


# ---------------------------------------------------------------------------------------------
# parsing any message


def test_syntax_constants_types_and_comments(tmp_path: Path) -> None:
    m = parse(
        tmp_path,
        "# Short description\n#\n# Longer text.\n\n# an internal comment\n"
        "uint32 MESSAGE_VERSION = 3\n" + HEAD + "int8 NEG = -5  # negative\nuint16 MASK = 0x8000\n"
        "float32 GAIN = 1.5e3\nbool ON = true\nfloat64 UNKNOWN = NaN\nuint8 LEADING = 010\n"
        "char letter\nchar[8] label # [-] Name\nbyte raw\nint64[2] pair\nfloat64 value # [@invalid INT16_MAX] big\n",
    )
    assert m.doc == "Short description\n\nLonger text."
    values = {c.name: c.value for c in m.constants}
    assert values["NEG"] == -5 and values["MASK"] == 0x8000 and values["GAIN"] == 1500.0 and values["ON"] is True
    assert math.isnan(float(values["UNKNOWN"])) and values["LEADING"] == 10
    assert next(c for c in m.constants if c.name == "NEG").doc == "negative"
    assert m.uorb is not None and m.uorb.message_version == 3
    assert m.field("letter").type == PrimitiveType(PrimitiveKind.CHAR, 8)
    label = m.field("label")
    assert label.type == StringType(8) and label.unit is not None
    assert label.unit.symbol == "1" and label.unit_text == "-"
    assert m.field("raw").type == PrimitiveType(PrimitiveKind.UINT, 8)
    assert m.field("pair").type == ArrayType(PrimitiveType(PrimitiveKind.INT, 64), 2, dynamic=False)
    assert m.field("value").invalid == Sentinel(32767.0, "INT16_MAX")
    assert m.field("letter").location.line == 14


def test_annotation_tags(tmp_path: Path) -> None:
    m = parse(
        tmp_path,
        HEAD + "float32 x # [m] [@frame NED] [@range , 3] [@invalid NaN when no fix] North position\n"
        "float32 y # [@range -1.5, 2e3] [dBm] [@future thing] Signal\nint16 t # [@invalid INT16_MIN]\n"
        "float32 z # [furlong/fortnight] Odd unit\nbool ok # [@invalid false] Valid flag\n",
    )
    x = m.field("x")
    assert x.range == Range(None, 3) and x.unit is not None and x.unit.symbol == "m"
    assert x.invalid is not None and x.invalid.is_nan and x.invalid.text == "NaN"
    assert x.annotations == (("invalid", "NaN when no fix"),) and x.doc == "North position" and x.frame == "NED"
    y = m.field("y")
    assert y.range == Range(-1.5, 2000.0) and y.annotations == (("future", "thing"),)
    assert y.unit is not None and y.unit.quantity == "unknown:dBm" and y.unit_text == "dBm"
    assert m.field("t").invalid == Sentinel(-32768, "INT16_MIN")
    z = m.field("z")
    assert z.unit is not None and z.unit.symbol == "furlong/fortnight" and z.unit.quantity.startswith("unknown:")
    assert m.field("ok").invalid == Sentinel(0, "false")


def test_enum_kinds(tmp_path: Path) -> None:
    m = parse(
        tmp_path,
        HEAD + "uint8 mode # [@enum MODE] Mode\nuint8 MODE_A = 1\nuint8 MODE_B = 2\nuint8 MODE_COUNT = 3\n"
        "uint16 flags # [@enum FLAG] Status flags\nuint16 FLAG_NONE = 0\nuint16 FLAG_A = 1\nuint16 FLAG_B = 4\n"
        "uint16 FLAG_C = 8\nuint32 bits # [@enum BIT] Error bitmask\nuint8 BIT_X = 0\nuint8 BIT_Y = 1\n"
        "int8 level # [@enum LEVEL] Level\nint8 LEVEL_LOW = -1\nint8 LEVEL_HIGH = 1\n",
    )
    kinds = {e.short_name: e.kind for e in m.enums}
    assert kinds == {
        "MODE": EnumKind.VALUE,
        "FLAG": EnumKind.BITMASK,
        "BIT": EnumKind.BIT_INDEX,
        "LEVEL": EnumKind.VALUE,
    }
    mode = m.enums[0]
    assert mode.name == "uorb.Sample.MODE" and [e.name for e in mode.entries] == ["MODE_A", "MODE_B"]
    assert [e.value for e in m.enums[3].entries] == [-1, 1]
    assert len(m.constants) == 11  # MODE_COUNT stays a constant


def test_topics(tmp_path: Path) -> None:
    m = parse(tmp_path, "# Doc line\n# TOPICS a_one b_two\n# TOPICS c_three\n" + HEAD, name="VehicleGpsPosition")
    assert m.uorb is not None and m.uorb.topics == ("a_one", "b_two", "c_three")
    assert m.doc == "Doc line"
    d = parse(tmp_path, HEAD, name="SensorGps")
    assert d.uorb is not None and d.uorb.topics == ("sensor_gps",) and d.uorb.message_version is None
    assert snake_case("Ekf2Timestamps") == "ekf2_timestamps"
    assert snake_case("BatteryStatusV0") == "battery_status_v0"


def test_nested_messages_and_layout(tmp_path: Path) -> None:
    write(tmp_path, "Inner", HEAD + "uint8 small\n")  # 8 + 1 -> padded to 16
    m = parse(tmp_path, "uint8 flag\nInner[2] pair\n" + HEAD + "uint16 word\nInner one\n", name="Outer")
    assert m.field("pair").type == ArrayType(CompositeType("uorb.Inner"), 2, dynamic=False)
    assert m.field("one").type == CompositeType("uorb.Inner")
    assert m.uorb is not None
    layout = [(s.name, s.offset, s.size, s.field) for s in m.uorb.layout]
    assert layout == [
        ("timestamp", 0, 8, "timestamp"),
        ("word", 8, 2, "word"),
        ("flag", 10, 1, "flag"),
        ("_padding0", 11, 5, None),
        ("pair", 16, 32, "pair"),
        ("one", 48, 16, "one"),
    ]
    assert m.uorb.struct_size == 64
    schema = uorb.parse_file(tmp_path / "Outer.msg", root=tmp_path)
    assert [x.qualified_name for x in schema.messages] == ["uorb.Inner", "uorb.Outer"]
    assert schema.sources == ("Inner.msg", "Outer.msg")
    inner = schema.message("uorb.Inner").uorb
    assert inner is not None and inner.layout[-1] == type(inner.layout[-1])("_padding0", 9, 7, None)


def test_parse_dir_walks_subdirectories(tmp_path: Path) -> None:
    (tmp_path / "sub").mkdir()
    write(tmp_path / "sub", "Zed", HEAD)
    write(tmp_path, "Alpha", HEAD)
    schema = uorb.parse_dir(tmp_path)
    assert [m.qualified_name for m in schema.messages] == ["uorb.Alpha", "uorb.Zed"]
    assert schema.message("uorb.Zed").location.file == "sub/Zed.msg"


# ---------------------------------------------------------------------------------------------
# errors: each names the file, the line and what was expected


@pytest.mark.parametrize(
    ("body", "line", "expected"),
    [
        (HEAD + "float32[] cells\n", 2, "expected a fixed array size"),
        (HEAD + "float32[<=4] cells\n", 2, "expected a fixed array size"),
        (HEAD + "float32[x] cells\n", 2, "expected a fixed array size"),
        (HEAD + "float32[0] cells\n", 2, "expected an array size of at least 1"),
        (HEAD + "Missing thing\n", 2, "expected a builtin type or a message defined in Missing.msg"),
        (HEAD + "string name\n", 2, "expected a fixed-size type: PX4 messages cannot hold 'string'"),
        (HEAD + "float32 x # [@range a]\n", 2, "expected '[@range <min>, <max>]'"),
        (HEAD + "float32 x # [@range 1]\n", 2, "expected '[@range <min>, <max>]'"),
        (HEAD + "float32 x # [@range ,]\n", 2, "expected at least one bound"),
        (HEAD + "float32 x # [@range 3, 1]\n", 2, "expected min <= max"),
        (HEAD + "float32 x # [@range 0, 1] [@range 0, 2]\n", 2, "expected one '[@range ...]'"),
        (HEAD + "uint8 x # [@invalid NaN]\n", 2, "expected an '@invalid' value a uint8 can hold"),
        (HEAD + "uint8 x # [@invalid -1]\n", 2, "expected an '@invalid' value a uint8 can hold"),
        (HEAD + "float32 x # [@invalid]\n", 2, "expected a value after '@invalid'"),
        (HEAD + "float32 x # [@invalid bogus]\n", 2, "expected a number, NaN or a limit name"),
        (HEAD + "float32 x # [@frame]\n", 2, "expected a value after '@frame'"),
        (HEAD + "float32 x # [@ NED]\n", 2, "expected a tag name after '@'"),
        (HEAD + "float32 x # [m\n", 2, "expected ']' to close"),
        (HEAD + "float32 x # [m] [s]\n", 2, "expected one unit"),
        (HEAD + "float32 x # [] text\n", 2, "expected a unit inside '[]'"),
        (HEAD + "float32 x # [@enum MODE]\nuint8 MODE_A = 1\n", 2, "expected '@enum' only on integer fields"),
        (HEAD + "uint8 m # [@enum M]\nfloat32 M_A = 1.5\n", 3, "expected an integer constant in enum M"),
        (HEAD + "uint8 x\nuint16 x\n", 3, "expected a unique name: 'x' is already defined on line 2"),
        (HEAD + "uint8 X = 1\nuint8 X = 2\n", 3, "expected a unique name"),
        (HEAD + "uint8 X = 300\n", 2, "expected a value in 0..255 for uint8, got 300"),
        (HEAD + "int8 X = -129\n", 2, "expected a value in -128..127 for int8"),
        (HEAD + "uint8 X = abc\n", 2, "expected an integer for a uint8 constant"),
        (HEAD + "uint8 X = 1.5\n", 2, "expected an integer for a uint8 constant"),
        (HEAD + "float32 X = fast\n", 2, "expected a float32 number"),
        (HEAD + "float32 X = 1e39\n", 2, "expected a float32 number"),
        (HEAD + "bool X = maybe\n", 2, "expected true, false, 1 or 0"),
        (HEAD + "uint8 X =\n", 2, "expected a constant '<type> <NAME> = <value>'"),
        (HEAD + "uint8 X = 1 2\n", 2, "expected a constant '<type> <NAME> = <value>'"),
        (HEAD + "uint8[2] X = 1\n", 2, "expected a builtin scalar type for constant 'X'"),
        (HEAD + "Other X = 1\n", 2, "expected a builtin scalar type for constant 'X'"),
        (HEAD + "float32 MESSAGE_VERSION = 1.0\n", 2, "expected MESSAGE_VERSION to be a non-negative integer"),
        (HEAD + "uint8\n", 2, "expected '<type> <name>'"),
        (HEAD + "uint8 a b\n", 2, "expected '<type> <name>'"),
        (HEAD + "uint8 Speed\n", 2, "expected a lower-case field name"),
        (HEAD + "uint8% x\n", 2, "expected a type such as 'float32'"),
        ("uint8 x\n", 1, "expected a 'uint64 timestamp' field"),
        ("uint8 y\nuint32 timestamp\n", 2, "expected 'timestamp' to be a uint64"),
        ("# TOPICS\n" + HEAD, 1, "expected topic names after '# TOPICS'"),
        ("# TOPICS a a\n" + HEAD, 1, "expected distinct topic names"),
        ("# TOPICS a-b\n" + HEAD, 1, "expected a topic name"),
    ],
)
def test_malformed_lines(tmp_path: Path, body: str, line: int, expected: str) -> None:
    err = error(tmp_path, body)
    assert (err.file, err.line) == ("Sample.msg", line)
    assert expected in err.message
    assert str(err).startswith(f"Sample.msg:{line}: expected")


def test_nesting_cycle_is_refused(tmp_path: Path) -> None:
    write(tmp_path, "Ping", HEAD + "Pong pong\n")
    write(tmp_path, "Pong", HEAD + "Ping ping\n")
    with pytest.raises(SchemaError) as info:
        uorb.parse_dir(tmp_path)
    assert (info.value.file, info.value.line) == ("Pong.msg", 2)
    assert "expected no nesting cycle: Ping contains this message" in info.value.message


def test_errors_in_nested_files_name_that_file(tmp_path: Path) -> None:
    write(tmp_path, "Inner", HEAD + "uint8 X = 256\n")
    err = error(tmp_path, HEAD + "Inner inner\n")
    assert (err.file, err.line) == ("Inner.msg", 2) and "expected a value in 0..255" in err.message


def test_file_level_errors(tmp_path: Path) -> None:
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    write(tmp_path / "a", "Same", HEAD)
    write(tmp_path / "b", "Same", HEAD)
    with pytest.raises(SchemaError) as info:
        uorb.parse_dir(tmp_path)
    assert (info.value.file, info.value.line) == ("b/Same.msg", 1)
    assert "expected a unique message name: uorb.Same is also defined in a/Same.msg" in info.value.message

    err = error(tmp_path, HEAD, name="bad-name")
    assert (err.file, err.line) == ("bad-name.msg", 1) and "expected a file named after its message" in err.message

    (tmp_path / "Latin.msg").write_bytes(b"uint64 timestamp\n# caf\xe9\n")
    with pytest.raises(SchemaError) as info:
        uorb.parse_file(tmp_path / "Latin.msg", root=tmp_path)
    assert (info.value.file, info.value.line) == ("Latin.msg", 2) and "expected UTF-8" in info.value.message

    with pytest.raises(SchemaError) as info:
        uorb.parse_file(tmp_path / "Absent.msg", root=tmp_path)
    assert info.value.file == "Absent.msg" and info.value.line == 0

    with pytest.raises(SchemaError) as info:
        uorb.parse_dir(tmp_path / "nowhere")
    assert "expected a directory" in info.value.message

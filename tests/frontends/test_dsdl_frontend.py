"""DSDL frontend: malformed input, constant expressions, bit lengths, docs/units/enums/sentinels."""

from __future__ import annotations

from pathlib import Path

import pytest

from codegen.errors import SchemaError
from codegen.frontends import dsdl
from codegen.frontends.dsdl.expr import ExpressionError, evaluate
from codegen.frontends.dsdl.signature import crc64we
from codegen.ir import (
    ArrayType,
    CastMode,
    CompositeType,
    DronecanKind,
    EnumKind,
    Location,
    PrimitiveKind,
    PrimitiveType,
    Range,
    Sentinel,
    units,
)

BUNDLED = Path(__file__).resolve().parents[2] / "schemas" / "dronecan"
BATTERY_INFO = BUNDLED / "uavcan" / "equipment" / "power" / "1092.BatteryInfo.uavcan"
BATTERY_AUX = BUNDLED / "ardupilot" / "equipment" / "power" / "20004.BatteryInfoAux.uavcan"


def write(root: Path, relative: str, text: str) -> Path:
    path = root / relative
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def parse_error(tmp_path: Path, text: str, name: str = "test/100.Broken.uavcan") -> SchemaError:
    root = tmp_path / "dsdl"
    path = write(root, name, text)
    with pytest.raises(SchemaError) as info:
        dsdl.parse_file(path, root=root)
    return info.value


# --------------------------------------------------------------------------------------------
# Malformed input: each error names the file, the line and what was expected


@pytest.mark.parametrize(
    ("text", "line", "expected"),
    [
        ("uint8 a\nfoo_bar b\n", 2, "unknown type 'foo_bar'"),
        ("uint8 a\nbits8 b\n", 2, "unknown primitive type 'bits8'"),
        ("uint65 a\n", 1, "expected a uint width between 2 and 64"),
        ("int1 a\n", 1, "expected a int width between 2 and 64 (use bool for one bit)"),
        ("uint128 a\n", 1, "expected a uint width between 2 and 64"),
        ("float8 a\n", 1, "expected float16, float32 or float64"),
        ("void65\n", 1, "expected a void width between 1 and 64"),
        ("uint8 a\nuint8[<x] b\n", 2, "expected an array bound [N], [<N] or [<=N] with an integer N"),
        ("uint8[<1] b\n", 1, "expected an array capacity of at least 1"),
        ("uint8[0] b\n", 1, "expected an array capacity of at least 1"),
        ("uint8[2][3] b\n", 1, "expected a one-dimensional array"),
        ("void2[3]\n", 1, "expected a non-void array element"),
        ("uint8 a\nuint8 X = 1 +\n", 2, "expected a constant expression"),
        ("uint8 X = 256\n", 1, "expected a value within [0, 255] for saturated uint8, got 256"),
        ("int8 X = -129\n", 1, "expected a value within [-128, 127]"),
        ("float16 X = 1e6\n", 1, "expected a value within [-65504.0, 65504.0]"),
        ("uint8 X = 1 / 0\n", 1, "expected a computable value"),
        ("uint8 X = 'ab'\n", 1, "expected a one-character literal"),
        ("uint8 X = foo\n", 1, "expected a literal, true or false"),
        ("uint8[2] X = 1\n", 1, "expected a primitive type"),
        ("uint8 X 1\n", 1, "expected '= <value>' after 'X'"),
        ("uint8 a\n\n# c\nuint8 a\n", 4, "expected a unique name; 'a' is already defined on line 1"),
        ("uint8 A = 1\nuint16 A\n", 2, "expected a unique name; 'A' is already defined on line 1"),
        ("uint8\n", 1, "expected '<type> <name>'"),
        ("uint8 9lives\n", 1, "expected a name of letters, digits and '_'"),
        ("saturated\n", 1, "expected a type after the cast mode"),
        ("truncated Other x\n", 1, "expected no cast mode before the composite type 'Other'"),
        ("@union\nuint8 a\n", 1, "expected at least 2 fields in a @union"),
        ("@union\nuint8 a\nvoid3\n", 3, "expected no void fields in a @union"),
        ("@union\n@union\nuint8 a\nuint8 b\n", 2, "expected a single @union"),
        ("@sealed\nuint8 a\n", 1, "expected '@union' (the only DSDL v0 directive)"),
        ("uint8 a\n---\nuint8 b\n---\n", 4, "expected at most one '---' service separator"),
        ("OVERRIDE_SIGNATURE xyz\n", 1, "expected a hexadecimal signature"),
        ("uint8 a\nMissing b\n", 2, "unresolvable type test.Missing: expected a definition file for it"),
        ("uint8 a\nother.Missing b\n", 2, "unresolvable type other.Missing"),
    ],
)
def test_malformed_definitions(tmp_path: Path, text: str, line: int, expected: str) -> None:
    err = parse_error(tmp_path, text)
    assert err.file == "test/100.Broken.uavcan"
    assert err.line == line
    assert expected in err.message


@pytest.mark.parametrize(
    "expression",
    [
        "__import__('os').system('touch pwned')",
        "open('pwned','w')",
        "().__class__.__bases__[0].__subclasses__()",
        "(lambda: 1)()",
        "[1][0]",
        "1 if 1 else 2",
        "2 ** 99999999",
        "1 << 99999999",
        "(" * 400 + "1" + ")" * 400,
    ],
)
def test_constant_expressions_never_execute_code(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, expression: str
) -> None:
    monkeypatch.chdir(tmp_path)
    err = parse_error(tmp_path, f"uint8 a\nuint8 X = {expression}\n")
    assert (err.file, err.line) == ("test/100.Broken.uavcan", 2)
    assert "expected" in err.message
    assert not (tmp_path / "pwned").exists() and not (tmp_path / "touchpwned").exists()


def test_nested_service_is_rejected(tmp_path: Path) -> None:
    root = tmp_path / "dsdl"
    write(root, "test/10.Svc.uavcan", "uint8 a\n---\nuint8 b\n")
    err = parse_error(tmp_path, "uint8 a\nSvc s\n")
    assert (err.file, err.line) == ("test/100.Broken.uavcan", 2)
    assert "expected a message type, test.Svc is a service" in err.message


def test_recursive_reference_is_rejected(tmp_path: Path) -> None:
    root = tmp_path / "dsdl"
    write(root, "test/B.uavcan", "uint8 x\ntest.Broken[<=2] back\n")
    err = parse_error(tmp_path, "uint8 a\nB b\n")
    assert err.file == "test/B.uavcan" and err.line == 2
    assert "expected no recursive type references: test.Broken -> test.B -> test.Broken" in err.message


def test_errors_in_a_referenced_file_name_that_file(tmp_path: Path) -> None:
    root = tmp_path / "dsdl"
    write(root, "test/Inner.uavcan", "uint8 x\nuint99 y\n")
    err = parse_error(tmp_path, "Inner inner\n")
    assert (err.file, err.line) == ("test/Inner.uavcan", 2)
    assert "expected a uint width between 2 and 64" in err.message


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("test/x.y.z.w.q.uavcan", "expected a file name like [<id>.]<Name>[.<major>.<minor>].uavcan"),
        ("test/abc.Foo.uavcan", "expected a file name like"),
        ("test/lowercase.uavcan", "expected a CamelCase type name, got 'lowercase'"),
        ("Bad-Ns/Foo.uavcan", "expected namespace components of lowercase letters"),
        ("Foo.uavcan", "expected a type inside a namespace"),
        ("test/70000.Foo.uavcan", "expected a message data type id within 0..65535, got 70000"),
    ],
)
def test_bad_file_names(tmp_path: Path, name: str, expected: str) -> None:
    err = parse_error(tmp_path, "uint8 a\n", name=name)
    assert err.file == name and err.line == 0
    assert expected in err.message


def test_service_id_range(tmp_path: Path) -> None:
    err = parse_error(tmp_path, "uint8 a\n---\nuint8 b\n", name="test/300.Svc.uavcan")
    assert (err.file, err.line) == ("test/300.Svc.uavcan", 0)
    assert "expected a service data type id within 0..255, got 300" in err.message


def test_file_outside_root(tmp_path: Path) -> None:
    path = write(tmp_path / "elsewhere", "test/Foo.uavcan", "uint8 a\n")
    with pytest.raises(SchemaError) as info:
        dsdl.parse_file(path, root=tmp_path / "dsdl")
    assert info.value.line == 0 and "expected the file below the DSDL root" in info.value.message


def test_undecodable_file(tmp_path: Path) -> None:
    root = tmp_path / "dsdl"
    path = root / "test" / "Foo.uavcan"
    path.parent.mkdir(parents=True)
    path.write_bytes(b"uint8 a\n# \xff\n")
    with pytest.raises(SchemaError) as info:
        dsdl.parse_file(path, root=root)
    assert (info.value.file, info.value.line) == ("test/Foo.uavcan", 2)
    assert "expected UTF-8 text" in info.value.message


def test_duplicate_ids_in_a_tree(tmp_path: Path) -> None:
    root = tmp_path / "dsdl"
    write(root, "test/500.First.uavcan", "uint8 a\n")
    write(root, "test/500.Second.uavcan", "uint8 a\n")
    with pytest.raises(SchemaError) as info:
        dsdl.parse_dir(root)
    assert (info.value.file, info.value.line) == ("test/500.Second.uavcan", 0)
    assert "expected a unique data type id; 500 is used by test/500.First.uavcan" in info.value.message


def test_two_files_for_one_type(tmp_path: Path) -> None:
    root = tmp_path / "dsdl"
    write(root, "test/Foo.uavcan", "uint8 a\n")
    write(root, "test/7.Foo.uavcan", "uint8 a\n")
    write(root, "test/User.uavcan", "Foo foo\n")
    with pytest.raises(SchemaError) as info:
        dsdl.parse_file(root / "test" / "User.uavcan", root=root)
    assert (info.value.file, info.value.line) == ("test/User.uavcan", 1)
    assert "expected one definition file for test.Foo, found 7.Foo.uavcan, Foo.uavcan" in info.value.message


# --------------------------------------------------------------------------------------------
# Well-formed input


def test_constant_expression_values() -> None:
    assert evaluate("1+2*3") == 7
    assert evaluate("1/4") == 0.25
    assert evaluate("-(1<<3)|1") == -7
    assert evaluate("0x10^0b11") == 19
    assert evaluate("~0&0xFF") == 255
    assert evaluate("7//2**1%3") == 0
    assert evaluate("true") == 1 and evaluate("false") == 0
    assert evaluate("'a'") == "a" and evaluate("'a'+1") == 98
    with pytest.raises(ExpressionError):
        evaluate("1.5|1")


def test_types_constants_and_arrays(tmp_path: Path) -> None:
    root = tmp_path / "dsdl"
    write(root, "test/Inner.uavcan", "uint8 x\n")
    path = write(
        root,
        "test/42.Things.uavcan",
        "saturated uint8 A = 'a'\n"
        "float32 THIRD = 1 / 3\n"
        "uint8 HALF = 7 / 2       # truncates like the reference\n"
        "bool FLAG = true\n"
        "int16 NEG = - ( 1 << 3 )\n"
        "truncated int12 t\n"
        "void3\n"
        "bool b\n"
        "float64[4] fixed\n"
        "uint7[<10] less\n"
        "uint7[<=0x10] at_most\n"
        "Inner inner\n"
        "test.Inner[<=2] inners\n",
    )
    schema = dsdl.parse_file(path, root=root)
    m = schema.message("dronecan.test.Things")
    assert [m.name for m in schema.messages] == ["Inner", "Things"]
    assert schema.sources == ("test/42.Things.uavcan", "test/Inner.uavcan")
    assert {c.name: c.value for c in m.constants} == {
        "A": 97, "THIRD": pytest.approx(1 / 3), "HALF": 3, "FLAG": True, "NEG": -8,
    }  # fmt: skip
    assert m.constants[4].type == PrimitiveType(PrimitiveKind.INT, 16)
    assert m.constants[2].doc == "truncates like the reference" and m.constants[2].location == Location(
        "test/42.Things.uavcan", 3
    )
    types = [f.type for f in m.fields]
    assert types[0] == PrimitiveType(PrimitiveKind.INT, 12, CastMode.TRUNCATED)
    assert m.fields[1].name == "" and m.fields[1].is_padding and types[1] == PrimitiveType(PrimitiveKind.VOID, 3)
    assert types[2] == PrimitiveType(PrimitiveKind.BOOL, 1)
    assert types[3] == ArrayType(PrimitiveType(PrimitiveKind.FLOAT, 64), 4, dynamic=False, min_length=4)
    assert types[4] == ArrayType(PrimitiveType(PrimitiveKind.UINT, 7), 9, dynamic=True)
    assert types[5] == ArrayType(PrimitiveType(PrimitiveKind.UINT, 7), 16, dynamic=True)
    assert types[6] == CompositeType("dronecan.test.Inner")
    assert types[7] == ArrayType(CompositeType("dronecan.test.Inner"), 2, dynamic=True)
    assert m.fields[7].location.line == 13
    info = m.dronecan
    assert info is not None and info.data_type_id == 42 and info.kind is DronecanKind.MESSAGE
    assert info.normalized_definition.splitlines()[1:4] == ["truncated int12 t", "void3", "saturated bool b"]
    # 12+3+1+256 + (4 + 9*7) + (5 + 16*7) + 8 + (2 + 2*8)
    assert info.max_bitlen == 12 + 3 + 1 + 256 + 67 + 117 + 8 + 18
    assert info.max_bitlen_tao == info.max_bitlen - 2  # the trailing Inner[<=2] loses its prefix
    assert info.min_bitlen == info.min_bitlen_tao == 12 + 3 + 1 + 256 + 8


def test_service_becomes_request_and_response(tmp_path: Path) -> None:
    root = tmp_path / "dsdl"
    path = write(
        root,
        "test/200.DoIt.uavcan",
        "# Does it.\n\nuint8 LEVEL_LOW = 0\nuint8 LEVEL_HIGH = 1\nuint8 level\n---\n@union\nuint8 ok\nuint8[<=4] why\n",
    )
    schema = dsdl.parse_file(path, root=root)
    req, resp = schema.message("dronecan.test.DoIt.Request"), schema.message("dronecan.test.DoIt.Response")
    assert (req.name, resp.name) == ("DoItRequest", "DoItResponse")
    assert req.dronecan is not None and resp.dronecan is not None
    assert (req.dronecan.kind, resp.dronecan.kind) == (DronecanKind.REQUEST, DronecanKind.RESPONSE)
    assert req.dronecan.signature == resp.dronecan.signature
    assert req.dronecan.data_type_id == resp.dronecan.data_type_id == 200
    assert (req.dronecan.union, resp.dronecan.union) == (False, True)
    assert req.dronecan.normalized_definition == (
        "test.DoIt\nsaturated uint8 level\n---\n@union\nsaturated uint8 ok\nsaturated uint8[<=4] why"
    )
    assert (resp.dronecan.max_bitlen, resp.dronecan.max_bitlen_tao) == (1 + 3 + 32, 1 + 32)
    assert resp.location.line == 6 and req.doc == "Does it."
    assert req.enums[0].name == "dronecan.test.DoIt.Request.LEVEL" and req.enums[0].kind is EnumKind.VALUE
    assert req.field("level").enums == ("dronecan.test.DoIt.Request.LEVEL",)


def test_crc64we_check_value() -> None:
    assert crc64we(b"123456789") == 0x62EC59E3F1A4F00A


def test_battery_info_bit_lengths() -> None:
    m = dsdl.parse_file(BATTERY_INFO).message("dronecan.uavcan.equipment.power.BatteryInfo")
    info = m.dronecan
    assert info is not None
    assert info.data_type_id == 1092 and info.signature == 0x249C26548A711966
    assert (info.min_bitlen, info.max_bitlen) == (184, 437)
    # model_name uint8[<32] is the tail: its 5-bit length prefix is dropped
    assert (info.min_bitlen_tao, info.max_bitlen_tao) == (184, 432)
    aux = dsdl.parse_file(BATTERY_AUX).message("dronecan.ardupilot.equipment.power.BatteryInfoAux").dronecan
    assert aux is not None and aux.max_bitlen_tao == aux.max_bitlen  # battery_id is last: no TAO


def test_battery_info_units_enums_sentinels() -> None:
    schema = dsdl.parse_file(BATTERY_INFO)
    m = schema.message("dronecan.uavcan.equipment.power.BatteryInfo")
    assert m.location.file == "uavcan/equipment/power/1092.BatteryInfo.uavcan"
    assert m.doc.startswith("State of one battery.")
    expected_units = {
        "temperature": ("Kelvin", "K"),
        "voltage": ("Volt", "V"),
        "current": ("Ampere", "A"),
        "average_power_10sec": ("Watt", "W"),
        "remaining_capacity_wh": ("Watt hours", "Wh"),
        "full_charge_capacity_wh": ("Watt hours", "Wh"),
        "hours_to_full_charge": ("Hours", "h"),
        "state_of_charge_pct": ("Percent", "%"),
    }
    for name, (text, symbol) in expected_units.items():
        f = m.field(name)
        assert (f.unit_text, f.unit) == (text, units.unit(symbol)), name
        assert "[" not in f.doc
    assert m.field("remaining_capacity_wh").doc == "Energy left; grows while charging"
    assert m.field("temperature").doc == "Measurements. Unknown values are NAN."
    assert m.field("status_flags").unit is None
    (flags,) = m.enums
    assert flags.name == "dronecan.uavcan.equipment.power.BatteryInfo.STATUS_FLAG"
    assert flags.kind is EnumKind.BITMASK
    assert [e.value for e in flags.entries] == [1 << i for i in range(11)]
    assert flags.entries[0].name == "STATUS_FLAG_IN_USE" and flags.entries[0].doc == "Supplying power"
    assert flags.doc.startswith("Status bits")
    assert m.field("status_flags").enums == (flags.name,)
    assert schema.enum(flags.name) == flags
    assert m.field("state_of_health_pct").invalid == Sentinel(127, "STATE_OF_HEALTH_UNKNOWN")
    assert m.field("state_of_charge_pct").invalid == Sentinel(127, "STATE_OF_CHARGE_UNKNOWN")  # dronecan/DSDL 2026
    assert m.field("state_of_charge_pct_stdev").invalid is None
    assert len(m.constants) == 13 and m.constants[-1].name == "STATE_OF_CHARGE_UNKNOWN"
    # the referenced-type-free file yields exactly one message
    assert [x.qualified_name for x in schema.messages] == [m.qualified_name]


def test_referenced_types_come_along_and_root_is_found() -> None:
    schema = dsdl.parse_file(BATTERY_AUX)
    assert [m.qualified_name for m in schema.messages] == [
        "dronecan.ardupilot.equipment.power.BatteryInfoAux",
        "dronecan.uavcan.Timestamp",
    ]
    aux = schema.messages[0]
    assert aux.field("timestamp").type == CompositeType("dronecan.uavcan.Timestamp")
    assert aux.field("voltage_cell").unit == units.unit("V")
    ts = schema.message("dronecan.uavcan.Timestamp")
    assert ts.location.file == "uavcan/Timestamp.uavcan"
    assert ts.field("usec").invalid == Sentinel(0, "UNKNOWN") and ts.field("usec").unit == units.unit("us")


def test_root_discovery_rules(tmp_path: Path) -> None:
    marked = write(tmp_path / "x" / "dsdl_specs", "dronecan/sensors/Foo.uavcan", "uint8 a\n")
    assert dsdl.parse_file(marked).messages[0].qualified_name == "dronecan.dronecan.sensors.Foo"
    plain = write(tmp_path / "Not-A-Namespace", "things/Bar.uavcan", "uint8 a\n")
    m = dsdl.parse_file(plain).messages[0]
    assert m.qualified_name == "dronecan.things.Bar" and m.location.file == "things/Bar.uavcan"


def test_comment_tags(tmp_path: Path) -> None:
    root = tmp_path / "dsdl"
    path = write(
        root,
        "test/Tags.uavcan",
        "float16 t # [C]  : pack temperature\n"
        "float16 r # [-1, 1.5] normalised\n"
        "float16 w # [Furlongs]\n"
        "uint8 x   # plain [not a tag]\n",
    )
    m = dsdl.parse_file(path, root=root).messages[0]
    assert (m.field("t").unit, m.field("t").unit_text, m.field("t").doc) == (
        units.unit("degC"),
        "C",
        "pack temperature",
    )
    assert (m.field("r").range, m.field("r").unit, m.field("r").doc) == (Range(-1, 1.5), None, "normalised")
    assert m.field("w").unit == units.opaque("Furlongs")
    assert (m.field("x").unit, m.field("x").doc) == (None, "plain [not a tag]")
    assert m.doc == ""


def test_parse_dir_is_deterministic() -> None:
    first, second = dsdl.parse_dir(BUNDLED), dsdl.parse_dir(BUNDLED)
    assert first == second
    names = [m.qualified_name for m in first.messages]
    assert names == sorted(names) and len(names) == 10


def test_invalid_tag_in_comments_gives_a_sentinel(tmp_path: Path) -> None:
    ns = tmp_path / "ns"
    ns.mkdir()
    (ns / "T.uavcan").write_text(
        "float16 a # [Volt] [@invalid NaN] pack voltage\nfloat32 b # [@invalid NaN]\nuint8 c # [@invalid 255]\n"
    )
    msg = dsdl.parse_file(ns / "T.uavcan", root=tmp_path).message("dronecan.ns.T")
    a, b, c = msg.fields
    assert a.invalid is not None and a.invalid.is_nan and a.unit is not None and a.unit.symbol == "V"
    assert a.doc == "pack voltage"
    assert b.invalid is not None and b.invalid.is_nan and b.unit is None
    assert c.invalid is not None and c.invalid.value == 255


def test_nan_sentinel_on_an_integer_is_an_error(tmp_path: Path) -> None:
    ns = tmp_path / "ns"
    ns.mkdir()
    (ns / "T.uavcan").write_text("uint8 ok\nuint8 c # [@invalid NaN]\n")
    with pytest.raises(SchemaError) as info:
        dsdl.parse_file(ns / "T.uavcan", root=tmp_path)
    assert info.value.line == 2 and "only on a float field" in info.value.message

"""The .dts/.dtsi parser (codegen.inputs.devicetree.read_dts) and the mapping onto the generated model.

Expected bytes follow dtc's output (checked against dtc itself in
conformance/test_dt_instances_dtschema.py); here each feature and each error path on its own.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from codegen.frontends import devicetree as frontend
from codegen.inputs.devicetree import (
    DevicetreeError,
    DtNode,
    field_for,
    find_compatible,
    monitored_batteries,
    node_to_model_dict,
    nodes_for_message,
    read_dts,
    read_nodes,
)
from codegen.ir import Message
from generated._meta import DataError
from generated.devicetree.power.supply import SimpleBattery

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data" / "devicetree"


@pytest.fixture(scope="module")
def message() -> Message:
    return frontend.parse_dir(ROOT / "schemas" / "devicetree").message("devicetree.power.supply.battery")


def _read(tmp_path: Path, text: str, name: str = "t.dts") -> list[DtNode]:
    path = tmp_path / name
    path.write_text(text)
    return read_dts(path, root=tmp_path)


def _node(nodes: list[DtNode], path: str) -> DtNode:
    return next(n for n in nodes if n.path == path)


def _err(tmp_path: Path, text: str, name: str = "t.dts") -> DevicetreeError:
    with pytest.raises(DevicetreeError) as info:
        _read(tmp_path, text, name)
    return info.value


# -- values ------------------------------------------------------------------------------------


def test_cells_expressions_and_negative_wrap(tmp_path: Path) -> None:
    nodes = _read(
        tmp_path,
        "/dts-v1/;\n/ { a = <(-10) 0x10 010 'A' (1 + 2 * 3) ((1 + 2) * 3) (7 / 2) (-7 % 3) (1 << 4) (~0)>;"
        " b = <(!0) (3 > 2) (2 <= 1) (1 == 1) (1 && 0) (0 || 2) (5 & 3 | 8 ^ 1) (0 ? 1 : 2) (10U)>; };\n",
    )
    a = nodes[0].properties["a"].cells()
    assert a == [0xFFFFFFF6, 16, 8, 65, 7, 9, 3, 0xFFFFFFFF & ((1 << 64) - 7) % 3, 16, 0xFFFFFFFF]
    assert nodes[0].properties["b"].cells() == [1, 1, 0, 1, 0, 1, (5 & 3) | (8 ^ 1), 2, 10]
    assert nodes[0].properties["a"].cells(signed=True)[0] == -10  # type: ignore[index]


def test_bits_bytes_strings_and_mixed_lists(tmp_path: Path) -> None:
    nodes = _read(
        tmp_path,
        "/dts-v1/;\n/ { b8 = /bits/ 8 <1 (-1) 0xff>; b16 = /bits/ 16 <0x1234>; b64 = /bits/ 64 <(-2)>;\n"
        ' raw = [00 1122 aB]; s = "a\\tb\\"\\x41\\101", "x"; mix = "m", <1>, [ff]; flag; };\n',
    )
    p = nodes[0].properties
    assert p["b8"].data == b"\x01\xff\xff"
    assert p["b16"].data == b"\x12\x34"
    assert p["b64"].data == b"\xff" * 7 + b"\xfe"
    assert p["raw"].data == b"\x00\x11\x22\xab"
    assert p["s"].strings() == ['a\tb"AA', "x"]
    assert p["mix"].data == b"m\0\0\0\0\1\xff"
    assert [part.kind for part in p["mix"].parts] == ["string", "cells", "bytes"]
    assert p["flag"].is_flag and p["flag"].guess() == "flag"


def test_labels_phandles_and_path_references(tmp_path: Path) -> None:
    nodes = _read(
        tmp_path,
        "/dts-v1/;\n/ {\n\tfixed: f { phandle = <1>; };\n\tbat: battery { };\n"
        "\tgauge { monitored-battery = <&bat>; both = <&fixed &{/battery}>; where = &bat, &{/f}; };\n};\n",
    )
    bat = _node(nodes, "/battery")
    assert bat.labels == ("bat",) and bat.label == "bat"
    assert bat.phandle == 2  # 1 is taken explicitly; dtc hands out the next free number
    assert list(bat.properties) == ["phandle"]  # appended by the reference, as dtc does
    gauge = _node(nodes, "/gauge")
    assert gauge.properties["both"].cells() == [1, 2]
    assert gauge.properties["where"].strings() == ["/battery", "/f"]
    assert monitored_batteries(nodes) == [(gauge, bat)]


def test_overlays_merge_delete_and_unit_addresses(tmp_path: Path) -> None:
    nodes = _read(
        tmp_path,
        "/dts-v1/;\n/memreserve/ 0x1000 0x100;\n/ { bat: battery@0 { a = <1>; b = <2>; old { }; }; };\n"
        "&bat { a = <3>; c = <4>; /delete-property/ b; /delete-node/ old; new { }; };\n"
        "/ { other { }; };\n/delete-node/ &{/other};\n&{/battery@0} { d; };\n",
    )
    bat = _node(nodes, "/battery@0")
    assert bat.name == "battery@0"
    assert list(bat.properties) == ["a", "c", "d"]  # a redefined in place, new ones appended
    assert bat.properties["a"].cells() == [3]
    assert [n.path for n in nodes] == ["/", "/battery@0", "/battery@0/new"]


def test_include_relative_to_the_including_file(tmp_path: Path) -> None:
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "a.dtsi").write_text('/include/ "b.dtsi"\n/ { a { x = <1>; }; };\n')
    (tmp_path / "sub" / "b.dtsi").write_text("/ { b: b { }; };\n")
    nodes = _read(tmp_path, '/dts-v1/;\n/include/ "sub/a.dtsi"\n&b { y; };\n')
    assert [n.path for n in nodes] == ["/", "/b", "/a"]
    b = _node(nodes, "/b")
    assert (b.file, b.line) == ("sub/b.dtsi", 1)
    assert (b.properties["y"].file, b.properties["y"].line) == ("t.dts", 3)


def test_comments_and_cpp_line_markers(tmp_path: Path) -> None:
    nodes = _read(
        tmp_path,
        '# 1 "board.dts"\n/dts-v1/; // header\n/* a\n block */ / {\n# 40 "battery.dtsi" 1\n\tbat { };\n};\n',
    )
    bat = _node(nodes, "/bat")
    assert (bat.file, bat.line) == ("battery.dtsi", 40)


@pytest.mark.skipif(shutil.which("cpp") is None, reason="cpp not installed")
def test_preprocessed_source_keeps_original_lines(tmp_path: Path) -> None:
    src = tmp_path / "m.dts"
    src.write_text(
        "/dts-v1/;\n#define UV(x) ((x) * 1000)\n#define GPIO_ACTIVE_HIGH 0\n/ {\n"
        "\tbattery {\n\t\tvoltage-min-design-microvolt = <UV(3200)>;\n\t\tflags = <GPIO_ACTIVE_HIGH>;\n\t};\n};\n"
    )
    out = tmp_path / "m.pp"
    cmd = ["cpp", "-nostdinc", "-undef", "-x", "assembler-with-cpp", "-o", str(out), str(src)]
    subprocess.run(cmd, check=True, capture_output=True, cwd=tmp_path)
    battery = _node(read_dts(out, root=tmp_path), "/battery")
    assert battery.properties["voltage-min-design-microvolt"].cells() == [3200000]
    assert (battery.file, battery.line, battery.properties["flags"].line) == ("m.dts", 5, 7)


def test_a_dtsi_needs_no_header(tmp_path: Path) -> None:
    nodes = _read(tmp_path, "/ { #address-cells = <1>; };\n", "part.dtsi")
    assert nodes[0].properties["#address-cells"].cells() == [1]


def test_read_nodes_picks_by_content(tmp_path: Path) -> None:
    path = tmp_path / "x.txt"
    path.write_text("/dts-v1/;\n/ { };\n")
    assert [n.path for n in read_nodes(path)] == ["/"]


# -- errors: each names the file and line and says what was expected -----------------------------


@pytest.mark.parametrize(
    ("text", "line", "message"),
    [
        ("/dts-v1/;\n#include <dt-bindings/gpio/gpio.h>\n/ { };\n", 2, "#include .*run the C preprocessor first"),
        ("/dts-v1/;\n#define X 1\n/ { };\n", 2, "#define .*cpp -nostdinc -undef -x assembler-with-cpp"),
        (
            "/dts-v1/;\n/ {\n\tgpios = <&gpio 3 GPIO_ACTIVE_HIGH>;\n};\n",
            3,
            "'GPIO_ACTIVE_HIGH' in cells looks like a C preprocessor macro",
        ),
        ("/dts-v1/;\n/ {\n\tx = FOO;\n};\n", 3, "'FOO' in a property value looks like a C preprocessor macro"),
        ("/ { };\n", 1, r"expected /dts-v1/; at the start"),
        ("/dts-v1/;\n/ {\n\ta = <1>\n};\n", 4, "expected ';' after property 'a'"),
        ("/dts-v1/;\n/ {\n\ta = <-1>;\n};\n", 3, r"negative numbers need parentheses"),
        ("/dts-v1/;\n/ { a = /bits/ 8 <256>; };\n", 2, "does not fit a 8-bit cell"),
        ("/dts-v1/;\n/ { a = /bits/ 12 <1>; };\n", 2, "expected 8, 16, 32 or 64"),
        ("/dts-v1/;\n/ { a = /bits/ 16 <&b>; b: b { }; };\n", 2, "only allowed in 32-bit cells"),
        ("/dts-v1/;\n/ { a = <(1 / 0)>; };\n", 2, "division by zero"),
        ("/dts-v1/;\n/ { a = <09>; };\n", 2, "not an octal number"),
        ("/dts-v1/;\n/ { a = [0 1]; };\n", 2, "expected hex byte pairs"),
        ("/dts-v1/;\n/ { a = 'ab'; };\n", 2, "expected a value"),
        ("/dts-v1/;\n/ { a = <'ab'>; };\n", 2, "character literal holds 2 bytes"),
        ('/dts-v1/;\n/ {\n\ta = "open;\n};\n', 3, "unterminated string"),
        ("/dts-v1/;\n/* never closed\n/ { };\n", 2, r"unterminated comment: expected \*/"),
        ("/dts-v1/;\n/ {\n\tx { };\n\ta = <1>;\n};\n", 4, "properties must come first"),
        ("/dts-v1/;\n/ {\n\ta = <&nowhere>;\n};\n", 3, "reference &nowhere names no node"),
        ("/dts-v1/;\n/ { };\n&nowhere { };\n", 3, "reference &nowhere names no node"),
        ("/dts-v1/;\n/ {\n\ta = <1>;\n\ta = <2>;\n};\n", 4, "duplicate property 'a'"),
        ("/dts-v1/;\n/ {\n\tx { };\n\tx { };\n};\n", 4, "duplicate node name 'x'"),
        ("/dts-v1/;\n/ {\n\tl: x { };\n\tl: y { };\n};\n", 4, "duplicate label 'l'"),
        ("/dts-v1/;\n/ {\n\tx {\n", 4, "expected '}' to close node x opened at t.dts:3"),
        ("/dts-v1/;\n/plugin/;\n/ { };\n", 2, "/plugin/ overlays are not supported"),
        ("/dts-v1/;\n", 2, "expected a root node"),
        ("/dts-v1/;\n/ { };\nfoo\n", 3, "expected '/ {', '&label {'"),
        ('/dts-v1/;\n/include/ "missing.dtsi"\n', 2, '"missing.dtsi": no such file'),
        ("/dts-v1/;\n/ { a = <0x10000000000000000>; };\n", 2, "does not fit 64 bits"),
    ],
)
def test_errors(tmp_path: Path, text: str, line: int, message: str) -> None:
    err = _err(tmp_path, text)
    assert (err.file, err.line) == ("t.dts", line), str(err)
    assert re.search(message, err.message), err.message


def test_include_cycle_is_reported(tmp_path: Path) -> None:
    (tmp_path / "a.dtsi").write_text('/include/ "b.dtsi"\n')
    (tmp_path / "b.dtsi").write_text('/ { };\n/include/ "a.dtsi"\n')
    err = _err(tmp_path, '/dts-v1/;\n/include/ "a.dtsi"\n')
    assert (err.file, err.line) == ("b.dtsi", 2)
    assert "/include/ cycle: t.dts -> a.dtsi -> b.dtsi -> a.dtsi" in err.message


def test_unreadable_file(tmp_path: Path) -> None:
    with pytest.raises(DevicetreeError, match="cannot read file") as info:
        read_dts(tmp_path / "absent.dts", root=tmp_path)
    assert (info.value.file, info.value.line) == ("absent.dts", 0)


# -- mapping onto the generated model ------------------------------------------------------------


def test_model_dict_of_the_binding_example(message: Message) -> None:
    nodes = read_dts(DATA / "valid_binding_example.dts")
    (battery,) = find_compatible(nodes, "simple-battery")
    assert nodes_for_message(nodes, message) == [battery]
    data = node_to_model_dict(battery, message)
    assert "phandle" not in data  # devicetree plumbing, not battery data
    assert data["compatible"] == ["simple-battery"]
    assert data["voltage-min-design-microvolt"] == [[12000000]]  # -microvolt is an int32 matrix
    assert data["charge-full-design-microamp-hours"] == [5000000]
    assert data["ocv-capacity-celsius"] == [-10, 25]  # int32: signed
    assert data["ocv-capacity-table-0"] == [[4150000, 100], [3920000, 70], [3760000, 30], [3400000, 0]]
    assert data["resistance-temp-table"] == [[25, 100], [10, 130], [0, 170], [0xFFFFFFF6, 250]]  # uint32 matrix
    assert data["operating-range-celsius"] == [-10, 60]
    model = SimpleBattery.from_dict(data)
    assert model.ocv_capacity_table_n["ocv-capacity-table-1"][0] == [4200000, 100]


def test_model_dict_of_includes_and_overlays(message: Message) -> None:
    (battery,) = find_compatible(read_dts(DATA / "valid_include_overlay.dts"), "simple-battery")
    data = node_to_model_dict(battery, message)
    assert "scratch" not in data and "status" not in data
    assert data["device-chemistry"] == "lithium-ion-polymer"
    assert data["voltage-max-design-microvolt"] == [[4200000]]
    assert data["volt-drop-thresh-microvolt"] == [[48000000]]
    assert data["volt-drop-0-microvolt"] == [[1, 2, 3]]  # rows of unknown length: one row, as dtschema cuts
    assert data["trickle-charge-current-microamp"] == [128000]
    SimpleBattery.from_dict(data)


def test_model_dict_hands_bad_values_to_from_dict(message: Message) -> None:
    (bad_type,) = find_compatible(read_dts(DATA / "invalid_wrong_type.dts"), "simple-battery")
    data = node_to_model_dict(bad_type, message)
    assert data["voltage-min-design-microvolt"] == b"3.2 V\0"
    with pytest.raises(DataError, match="voltage-min-design-microvolt: expected a list"):
        SimpleBattery.from_dict(data)
    (unknown,) = find_compatible(read_dts(DATA / "invalid_unknown_property.dts"), "simple-battery")
    data = node_to_model_dict(unknown, message)
    assert data["acme,secret-sauce"] == [1]
    with pytest.raises(DataError, match="acme,secret-sauce"):
        SimpleBattery.from_dict(data)


def test_field_for_patterns(message: Message) -> None:
    assert field_for(message, "ocv-capacity-table-12").name == "^ocv-capacity-table-[0-9]+$"  # type: ignore[union-attr]
    assert field_for(message, "volt-drop-3-microvolt").name == "^volt-drop-[0-9]-microvolt"  # type: ignore[union-attr]
    assert field_for(message, "ocv-capacity-table-x") is None

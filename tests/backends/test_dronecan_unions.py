"""The generated DroneCAN union API: one branch held at a time, selected by assigning it.

Small DSDL definitions written here (a union with a composite, a number and an array branch,
nested in a structure), encoded as pydronecan encodes the same definitions;
conformance/test_dronecan_codec.py does the same for every union of pydronecan's DSDL tree.
"""

from __future__ import annotations

import importlib
import json
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from codegen.backends.json_schema import message_json_schema
from codegen.backends.python.writer import generate
from codegen.frontends import dsdl

DEFINITIONS = {
    "Nothing.uavcan": "",
    "Pick.uavcan": "@union\ntest.Nothing none\nint16 number\nuint8[<=4] raw\nfloat16 half\n",
    "Holder.uavcan": "uint8 index\ntest.Pick pick\n",
}


@pytest.fixture(scope="module")
def reference(mod: Any) -> dict[str, Any]:
    """pydronecan's types for the same definition files."""
    pydronecan = pytest.importorskip("dronecan")
    folder = mod.__file__.split("/out/")[0] + "/dsdl/test"
    return {t.full_name: t for t in pydronecan.dsdl.parse_namespaces([folder])}


def _ref_bytes(reference: dict[str, Any], name: str, tao: bool = True, **values: Any) -> bytes:
    from dronecan import transport

    obj = transport.CompoundValue(reference[f"test.{name}"])
    for key, value in values.items():
        setattr(obj, key, value)
    return bytes(transport.bytes_from_bits(obj._pack(tao)))


@pytest.fixture(scope="module")
def mod(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Any]:
    base = tmp_path_factory.mktemp("dc_union")
    (base / "dsdl" / "test").mkdir(parents=True)
    for name, text in DEFINITIONS.items():
        (base / "dsdl" / "test" / name).write_text(text)
    generate(dsdl.parse_dir(base / "dsdl"), base / "out" / "dc_union")
    sys.path.insert(0, str(base / "out"))
    try:
        yield importlib.import_module("dc_union.dronecan.test")
    finally:
        sys.path.remove(str(base / "out"))
        for name in [n for n in sys.modules if n.split(".")[0] == "dc_union"]:
            del sys.modules[name]


def test_the_field_given_is_the_branch_encoded(mod: Any, reference: dict[str, Any]) -> None:
    pick = mod.Pick(number=-2)
    assert pick.union_field == "number"
    assert (pick.none, pick.raw, pick.half) == (None, None, None)
    assert pick.encode() == _ref_bytes(reference, "Pick", number=-2)
    assert mod.Pick.decode(pick.encode()) == pick
    assert mod.Pick(raw=b"xyz").encode(tao=False) == _ref_bytes(reference, "Pick", False, raw=b"xyz")
    assert mod.Pick(half=0.5).encode() == _ref_bytes(reference, "Pick", half=0.5)


def test_no_field_given_holds_the_first_branch_at_its_default(mod: Any, reference: dict[str, Any]) -> None:
    pick = mod.Pick()
    assert pick.union_field == "none" and pick.none == mod.Nothing()
    assert pick.encode() == _ref_bytes(reference, "Pick") == b"\x00"
    assert mod.Holder().pick == pick


def test_two_fields_given_is_a_type_error(mod: Any) -> None:
    with pytest.raises(TypeError, match="Pick: a union holds one field, got number, raw"):
        mod.Pick(number=1, raw=b"x")


def test_assigning_a_branch_selects_it_and_drops_the_others(mod: Any, reference: dict[str, Any]) -> None:
    pick = mod.Pick(number=5)
    pick.raw = b"ab"
    assert pick.union_field == "raw" and pick.number is None
    assert pick.encode() == _ref_bytes(reference, "Pick", raw=b"ab")
    pick.union_field = "half"  # switching by name gives the branch a fresh default
    assert (pick.half, pick.raw) == (0.0, None)
    pick.half = 1.5
    pick.union_field = "half"  # the held branch keeps its value
    assert pick.half == 1.5


def test_branch_survives_to_dict_from_dict_and_json(mod: Any) -> None:
    for pick in (mod.Pick(), mod.Pick(number=0), mod.Pick(raw=b""), mod.Pick(half=float("nan"))):
        data = pick.to_dict()
        assert len(data) == 1
        assert mod.Pick.from_dict(data) == pick
        assert mod.Pick.from_dict(json.loads(json.dumps(data))) == pick
    holder = mod.Holder(index=3, pick=mod.Pick(raw=b"\x01\x02"))
    assert holder.to_dict() == {"index": 3, "pick": {"raw": [1, 2]}}
    assert mod.Holder.from_dict(json.loads(json.dumps(holder.to_dict()))) == holder


def test_from_dict_accepts_the_union_field_key(mod: Any) -> None:
    assert mod.Pick.from_dict({"union_field": "number", "number": 9}) == mod.Pick(number=9)
    assert mod.Pick.from_dict({"union_field": "raw"}) == mod.Pick(raw=b"")
    assert mod.Pick.from_dict({}) == mod.Pick()


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({"union_field": "nope"}, "Pick.union_field: expected one of none, number, raw, half, got 'nope'"),
        ({"union_field": 1}, "Pick.union_field: expected one of none, number, raw, half, got 1"),
        ({"union_field": "raw", "number": 1}, r"Pick.union_field: expected the branch the data gives \(number\)"),
        ({"number": 1, "half": 2.0}, r"Pick: expected one field of the union \(none, number, raw, half\)"),
        ({"number": None}, "number: expected an integer, got None"),
    ],
)
def test_from_dict_refuses_data_naming_no_single_branch(mod: Any, data: dict[str, Any], message: str) -> None:
    runtime = importlib.import_module("dc_union._meta")
    with pytest.raises(runtime.DataError, match=message):
        mod.Pick.from_dict(data)


def test_validate_rejects_an_impossible_branch(mod: Any) -> None:
    pick = mod.Pick(number=3)
    assert pick.validate() == []
    assert pick.is_known("number") and not pick.is_known("raw")
    pick.union_field = "bogus"
    [found] = pick.validate()
    assert (found.path, found.rule, found.value) == ("union_field", "union", "bogus")
    assert "not a field of this union (one of none, number, raw, half)" in found.message
    pick = mod.Pick(number=3)
    pick.number = None
    [found] = pick.validate()
    assert (found.path, found.rule) == ("number", "union")
    runtime = importlib.import_module("dc_union._dronecan")
    with pytest.raises(runtime.EncodeError, match=r"Pick\.number: the selected branch holds None"):
        pick.encode()
    object.__setattr__(pick, "number", 4)  # bypassing the hooks: two branches hold values
    object.__setattr__(pick, "half", 1.0)
    assert [v.rule for v in pick.validate()] == ["union"]
    holder = mod.Holder(pick=mod.Pick(number=1))
    holder.pick.union_field = "bogus"
    assert [v.path for v in holder.validate()] == ["pick.union_field"]


def test_a_branch_out_of_range_is_reported(mod: Any) -> None:
    found = mod.Pick(number=40000).validate()
    assert [(v.path, v.rule) for v in found] == [("number", "type-bounds")]


@pytest.mark.parametrize(
    "data",
    [{}, {"number": 1}, {"union_field": "raw"}, {"union_field": "raw", "raw": [1]}, {"union_field": "raw", "number": 1},
     {"number": 1, "half": 2.0}, {"union_field": "nope"}],
)  # fmt: skip
def test_json_schema_accepts_what_from_dict_accepts(mod: Any, data: dict[str, Any]) -> None:
    jsonschema = pytest.importorskip("jsonschema")
    folder = Path(mod.__file__.split("/out/")[0]) / "dsdl"
    schema = dsdl.parse_dir(folder)
    validator = jsonschema.Draft202012Validator(message_json_schema(schema, schema.message("dronecan.test.Pick")))
    runtime = importlib.import_module("dc_union._meta")
    try:
        mod.Pick.from_dict(data)
        accepted = True
    except runtime.DataError:
        accepted = False
    assert validator.is_valid(data) == accepted

"""``battgen vectors``: every field's edges are in the vectors, and every vector replays -- through
the generated converter called directly (not through the vector writer), and, for MAVLink targets,
through pymavlink's encoder (every expected output fits BATTERY_STATUS on the wire)."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

import pytest
from pymavlink.dialects.v20 import common as mavlink2

from codegen.apps.conversion.vectors import vectors_document
from codegen.cli.main import main
from codegen.frontends.loader import load
from codegen.ir import EnumKind
from codegen.ir.numbers import to_json_data
from generated import convert

ROOT = Path(__file__).resolve().parents[2]
SCHEMA = load([ROOT / "schemas"])
PAIRS = [
    ("uorb", "mavlink", "strict"),
    ("uorb", "mavlink", "px4"),
    ("uorb", "dronecan", "px4"),
    ("dronecan", "uorb", "strict"),
    ("mavlink", "uorb", "strict"),
    ("uorb_v0", "uorb", "strict"),
    ("dronecan", "concepts", "strict"),
]


@pytest.fixture(scope="module")
def documents() -> dict[tuple[str, str, str], dict[str, Any]]:
    return {pair: vectors_document(*pair) for pair in PAIRS}


def _replay(source: str, target: str, policy: str, data: dict[str, Any]) -> dict[str, Any]:
    """The generated converter on one vector's input, without battgen's apps layer."""
    items = convert.ENDPOINTS[source]
    parts = [data.get(a) for a, _ in items] if len(items) > 1 else [data]
    objs = [cls.from_dict(p) if p is not None else None for (_, cls), p in zip(items, parts, strict=True)]
    report = convert.LossReport()
    try:
        result = convert.converter(source, target)(*objs, policy=policy, report=report)
    except ValueError as exc:
        return {"error": str(exc)}
    seq = result if isinstance(result, tuple) else (result,)
    targets = convert.ENDPOINTS[target]
    plain = (
        to_json_data(seq[0].to_dict())
        if len(targets) == 1
        else {a: to_json_data(o.to_dict()) for (a, _), o in zip(targets, seq, strict=True) if o is not None}
    )
    return {"output": plain, "loss": report.to_dict()}


@pytest.mark.parametrize("pair", PAIRS, ids=["-".join(p) for p in PAIRS])
def test_every_vector_replays(
    documents: dict[tuple[str, str, str], dict[str, Any]], pair: tuple[str, str, str]
) -> None:
    doc = documents[pair]
    assert (doc["source"], doc["target"], doc["policy"]) == pair and doc["battgen_vectors"] == 1
    converted = 0
    for v in doc["vectors"]:
        expected = {k: v[k] for k in ("output", "loss", "error") if k in v}
        assert _replay(*pair, json.loads(json.dumps(v["input"]))) == expected, v["id"]
        converted += "output" in v
    assert converted > 0.8 * len(doc["vectors"])


@pytest.mark.parametrize("pair", PAIRS, ids=["-".join(p) for p in PAIRS])
def test_every_field_sentinel_and_enum_entry_is_covered(
    documents: dict[tuple[str, str, str], dict[str, Any]], pair: tuple[str, str, str]
) -> None:
    doc = documents[pair]
    schema = SCHEMA
    coverage = doc["coverage"]
    for alias, cls in convert.ENDPOINTS[pair[0]]:
        for f in dataclasses.fields(cls):
            edges = coverage[f"{alias}.{f.name}"]  # every field of every source message is varied
            if "." in f.metadata["type"]:  # a composite (uavcan.Timestamp): kept at its default
                assert edges == ["default"]
                continue
            if f.metadata["invalid"] is not None:
                assert "unknown" in edges, f.name
            if f.metadata["minimum"] is not None:
                assert {"minimum", "below-minimum"} <= set(edges), f.name
            for name in f.metadata["enums"]:
                enum = schema.enum(name)
                assert {f"{enum.short_name}.{e.name}" for e in enum.entries} <= set(edges), name
                if enum.kind is not EnumKind.VALUE:  # each bit on its own
                    assert all(f"{enum.short_name}.{e.name}" in edges for e in enum.entries)
    ids = [v["id"] for v in doc["vectors"]]
    assert len(ids) == len(set(ids)) and ids[0] == "baseline"


def test_mavlink_outputs_fit_the_wire_as_pymavlink_encodes_it(
    documents: dict[tuple[str, str, str], dict[str, Any]],
) -> None:
    for pair in [p for p in PAIRS if p[1] == "mavlink"]:
        for v in documents[pair]["vectors"]:
            if "output" not in v:
                continue
            o = v["output"]
            msg = mavlink2.MAVLink_battery_status_message(
                o["id"], o["battery_function"], o["type"], o["temperature"], o["voltages"], o["current_battery"],
                o["current_consumed"], o["energy_consumed"], o["battery_remaining"], o["time_remaining"],
                o["charge_state"], o["voltages_ext"], o["mode"], o["fault_bitmask"],
            )  # fmt: skip
            mav = mavlink2.MAVLink(None, srcSystem=1, srcComponent=1)
            frame = msg.pack(mav)  # struct.error for any value its wire type cannot hold
            back = mav.decode(bytearray(frame))
            assert list(back.voltages) == o["voltages"] and back.temperature == o["temperature"], v["id"]


def test_the_nan_cell_edge_is_a_vector(documents: dict[tuple[str, str, str], dict[str, Any]]) -> None:
    """The case that once stopped a strict conversion: a cell voltage unknown among known ones."""
    (v,) = [v for v in documents[("uorb", "mavlink", "strict")]["vectors"] if v["id"] == "status.voltage_cell_v/nan"]
    assert v["input"]["voltage_cell_v"][0] == "NaN" and "error" not in v
    vectors = documents[("uorb", "mavlink", "strict")]["vectors"]
    (inside,) = [v for v in vectors if v["id"] == "status.voltage_cell_v/array-sentinel-inside"]
    assert inside["output"]["voltages"][:3] == [3500, 65535, 3500]  # the unknown cell: MAVLink's "no cell"
    assert {
        "kind": "unrepresentable",
        "field": "mavlink.BATTERY_STATUS.voltages",
        "detail": "cell 2 unknown (NaN), sent as 65535 (no cell)",
    } in inside["loss"]


def test_cli_writes_the_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "v.json"
    code = main(["vectors", "--from", "uorb", "--to", "mavlink", "--policy", "px4", "-o", str(out)])
    _, err = capsys.readouterr()
    doc = json.loads(out.read_text())
    assert code == 0 and err.startswith(f"wrote {len(doc['vectors'])} vectors of uorb -> mavlink (px4) to {out}")
    assert doc["coverage"]
    code = main(["vectors", "--from", "concepts", "--to", "mavlink"])
    assert code == 2 and "vectors are made for message sides" in capsys.readouterr().err
    code = main(["vectors", "--from", "uorb", "--to", "mavlink", "-o", str(tmp_path / "no" / "v.json")])
    assert code == 2 and "does not exist" in capsys.readouterr().err

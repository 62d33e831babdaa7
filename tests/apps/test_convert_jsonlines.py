"""``battgen convert``'s JSON Lines reading and writing through orjson give exactly the standard library's values
and bytes: on the usual records and on each case where the two differ (big integers, NaN, exponents, text with
separators or non-ASCII, surrogates), which the module hands to json."""

from __future__ import annotations

import json
import math
from typing import Any

import pytest

from codegen.apps.conversion.jsonlines import encode_record
from codegen.inputs.jsonl_blocks import loads_line as loads

LINES = [
    '{"voltage": 15.046, "current": 17.35, "remaining_capacity_wh": "NaN", "battery_id": 2}\n',
    '{"a": 1, "b": 2, "a": 3}',  # a repeated key: the last value, at the first place
    '{"big": 99999999999999999999999}',  # beyond 64 bits: orjson would read a float
    '{"n": 9223372036854775807, "m": -9223372036854775808, "z": -0}',
    '{"x": 0.1000000000000000055511151231257827, "y": 1e400, "w": -1e-400}',
    '{"nan": NaN, "inf": Infinity, "ninf": -Infinity}',  # json's extension, orjson's error
    '{"s": "\\ud800", "t": "caf\\u00e9 \\u2028"}',  # a lone surrogate: json keeps it
    '{"f": [1.5, 2.25e-7, 3e16, 12.600000381469727]}',
    '  [1, 2, {"k": null}]  \r\n',
]

BAD_LINES = ['{"a": 1,}', "{'a': 1}", "[1, 2", '{"a": 01}', '"\\x"', "", "NaNa", '{"a": 1} 2']


@pytest.mark.parametrize("line", LINES)
def test_loads_reads_what_json_reads(line: str) -> None:
    got, want = loads(line), json.loads(line)
    assert repr(got) == repr(want)  # repr: NaN compares unequal, and int 1 == float 1.0 would hide a type change


@pytest.mark.parametrize("line", BAD_LINES)
def test_loads_raises_json_error(line: str) -> None:
    with pytest.raises(json.JSONDecodeError) as ours:
        loads(line)
    with pytest.raises(json.JSONDecodeError) as theirs:
        json.loads(line)
    assert (ours.value.msg, ours.value.pos) == (theirs.value.msg, theirs.value.pos)


RECORDS: list[Any] = [
    {"id": 0, "voltages": [15046, 65535, 65535], "current_battery": 1735, "ok": True, "none": None},
    {"voltage_v": 15.045999526977539, "remaining": 0.8299999833106995, "cells": [4.2, 0.0, -0.0]},
    {"tiny": 1e-05, "huge": 1e16, "just_below": 9999999999999998.0, "just_above_tiny": 0.0001},
    {"text": "a, b: c", "quote": 'say "hi"', "back": "a\\b", "uni": "café", "ctl": "\x01", "empty": ""},
    {"nested": {"info": {"voltage": 12.5, "cells": [1, 2]}, "aux": {"nominal_voltage": 14.8}}, "list": []},
    {"big": 2**70, "neg": -(2**63), "max": 2**64 - 1},
    {"k,ey": 1},
    {1: "integer key"},
    {"record": {"a": 1}, "loss": [{"kind": "unknown", "field": "mavlink.BATTERY_STATUS.voltages"}]},
    [1, 2, 3],
    {"objects in a list": [{"a": 1}]},
    {"is_true": 1.5e-07, "n": 1},  # a key holding "true" beside an exponent orjson spells 1.5e-7
    {"x": 1e-05, "flag": True, "off": False},  # orjson: 0.00001
    {"x": 10.00001, "y": 0.0001, "z": 1e16, "w": -1.5e300},
    {"t": True, "f": False, "x": 2.5, "cells": [True, 1, 2.0]},
    {"e": 1, "ee": [2, 3], "connected": True},
    {},
]


@pytest.mark.parametrize("record", RECORDS)
def test_encode_record_writes_json_dumps_bytes(record: Any) -> None:
    assert encode_record(record) == json.dumps(record, allow_nan=False).encode() + b"\n"


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf])
def test_encode_record_refuses_nan_as_json_does(value: float) -> None:
    with pytest.raises(ValueError):
        encode_record({"x": value})
    with pytest.raises(ValueError):
        encode_record({"x": [1.0, value]})


def test_integral_classes_are_told_by_their_field_types() -> None:
    import generated.dronecan.uavcan.equipment.power as power
    import generated.mavlink as mavlink
    import generated.uorb as uorb
    from codegen.apps.conversion.jsonlines import integral

    assert integral(mavlink.BatteryStatus)  # MAVLink's BATTERY_STATUS: integers and arrays of them only
    assert not integral(uorb.BatteryStatus)  # floats
    assert not integral(power.BatteryInfo)
    assert not integral(dict)


@pytest.mark.parametrize(
    "record",
    [
        {"id": 0, "voltages": [15046, 65535], "current_battery": -1, "flag": True, "other": False},
        {"a": 2**64 - 1, "b": -(2**63), "c": [], "d": 0},
        {"big": 2**64},  # beyond orjson: None, json writes it
    ],
)
def test_an_integral_line_is_what_json_writes(record: dict[str, Any]) -> None:
    from codegen.apps.conversion.jsonlines import integral_line

    got = integral_line(record)
    if "big" in record:
        assert got is None
    else:
        assert got == (json.dumps(record, allow_nan=False) + "\n").encode()

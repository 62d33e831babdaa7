"""Every PX4 message definition of main and releases 1.14-1.18 (../shared/corpus/upstream/px4_msgs/) reads
into the IR in one ``battgen ir`` run per folder, laid out as PX4 lays out its C structs.

Two references for the layout: PX4's padding rule restated here from the facts of its generator
(Tools/msg/px_generate_uorb_topic_helper.py: fields stable-sorted by element size, largest first,
nested structs last with size 0 for sorting; ``_paddingN`` bytes to a multiple of 8 before each nested
struct and at the end, a nested struct counting with its padded size), computed from the raw .msg
lines without our frontend; and the struct layouts a real PX4 1.15 (development) build wrote into a
flight log, for every topic whose fields that release defines identically.
"""

from __future__ import annotations

import io
import json
import re
from collections import Counter
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path
from typing import Any

import pytest
from pyulog import ULog
from shared_data import REAL_LOGS, UPSTREAM, missing

from codegen.cli.main import main
from codegen.ir.json_form import validate_ir_json

CORPUS = UPSTREAM / "px4_msgs"
VERSIONS = ("main", "1.14", "1.15", "1.16", "1.17", "1.18")
EVENTS_LOG = REAL_LOGS / "sample_px4_events.ulg"  # PX4 v1.15.0 development build

# element sizes PX4's generator knows (msgtype_size_map); anything else is a nested message
SIZES = {"int8": 1, "int16": 2, "int32": 4, "int64": 8, "uint8": 1, "uint16": 2, "uint32": 4, "uint64": 8,
         "float32": 4, "float64": 8, "bool": 1, "char": 1}  # fmt: skip
Slot = tuple[str, int, int]  # (name, offset, size)

# What the corpus holds that PX4's doc linter (or its 1.16 syntax) flags: accepted, with a warning each
EXPECTED_WARNINGS = {
    "main": {"invalid-value": 3, "frame-as-unit": 3, "enum-prefix": 2, "range-without-at": 1},
    "1.14": {"range-without-at": 1},
    "1.15": {"range-without-at": 1},
    "1.16": {"range-without-at": 10},
    "1.17": {"frame-as-unit": 6, "range-without-at": 1},
    "1.18": {"invalid-value": 3, "frame-as-unit": 3, "enum-prefix": 2, "range-without-at": 1},
}


def run_ir(folder: Path) -> tuple[int, dict[str, Any], str]:
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        code = main(["ir", str(folder)])
    return code, json.loads(out.getvalue() or "{}"), err.getvalue()


@pytest.fixture(scope="module", params=VERSIONS)
def version_ir(request: pytest.FixtureRequest) -> tuple[str, dict[str, Any], str]:
    code, data, err = run_ir(CORPUS / request.param)
    assert code == 0, err
    return request.param, data, err


def raw_fields(path: Path) -> list[tuple[str, int, str]]:
    """(base type, array length or 1, name) of each field line, read with nothing but a split."""
    fields = []
    for line in path.read_text(encoding="utf-8").splitlines():
        code = line.split("#", 1)[0].strip()
        if not code or "=" in code:
            continue
        type_token, name = code.split()
        match = re.fullmatch(r"(?:\w+/)?(\w+)(?:\[(\d+)\])?", type_token)
        assert match, f"{path.name}: {line}"
        fields.append((match.group(1), int(match.group(2) or 1), name))
    return fields


def px4_layout(folder: Path, name: str, memo: dict[str, tuple[int, list[Slot]]]) -> tuple[int, list[Slot]]:
    """(struct size, slots) by PX4's generator rule, for message ``name`` of ``folder``."""
    if name in memo:
        return memo[name]
    fields = sorted(raw_fields(folder / f"{name}.msg"), key=lambda f: SIZES.get(f[0], 0), reverse=True)
    slots: list[Slot] = []
    offset = paddings = 0
    for base, count, field_name in fields:
        if base in SIZES:
            size = SIZES[base] * count
        else:
            if offset % 8:
                slots.append((f"_padding{paddings}", offset, 8 - offset % 8))
                paddings, offset = paddings + 1, offset + 8 - offset % 8
            size = px4_layout(folder, base, memo)[0] * count
        slots.append((field_name, offset, size))
        offset += size
    if offset % 8:
        slots.append((f"_padding{paddings}", offset, 8 - offset % 8))
        offset += 8 - offset % 8
    memo[name] = (offset, slots)
    return memo[name]


def test_every_message_is_in_the_ir_in_one_run(version_ir: tuple[str, dict[str, Any], str]) -> None:
    version, data, _ = version_ir
    files = sorted(p.stem for p in (CORPUS / version).glob("*.msg"))
    assert files, f"no .msg files in {version}"
    assert sorted(m["name"] for m in data["messages"]) == files
    assert all(m["format"] == "uorb" and m["uorb"]["struct_size"] > 0 for m in data["messages"])


def test_warnings_are_located_and_counted(version_ir: tuple[str, dict[str, Any], str]) -> None:
    version, _, err = version_ir
    lines = err.splitlines()
    pattern = re.compile(r"battgen: (\w+)\.msg:(\d+): warning: .+")
    assert all(pattern.fullmatch(line) for line in lines), lines
    kinds = Counter(_warning_kind(line) for line in lines)
    assert kinds == Counter(EXPECTED_WARNINGS[version])


def _warning_kind(line: str) -> str:
    for needle, kind in (("as the range", "range-without-at"), ("as the frame", "frame-as-unit"),
                         ("@enum", "enum-prefix"), ("on a char array", "invalid-value")):  # fmt: skip
        if needle in line:
            return kind
    return line


def test_layouts_follow_px4s_generator_rule(version_ir: tuple[str, dict[str, Any], str]) -> None:
    version, data, _ = version_ir
    memo: dict[str, tuple[int, list[Slot]]] = {}
    mismatches = []
    for message in data["messages"]:
        size, slots = px4_layout(CORPUS / version, message["name"], memo)
        ours = [(s["name"], s["offset"], s["size"]) for s in message["uorb"]["layout"]]
        if (message["uorb"]["struct_size"], ours) != (size, slots):
            mismatches.append(
                f"{message['name']}: ours {ours} size {message['uorb']['struct_size']}, PX4 {slots} {size}"
            )
    assert not mismatches, "\n".join(mismatches)
    assert any(name.startswith("_padding") for _, slots in memo.values() for name, _, _ in slots)


def test_the_ir_of_main_conforms_to_the_ir_schema() -> None:
    code, data, err = run_ir(CORPUS / "main")
    assert code == 0, err
    assert validate_ir_json(data) == []


def test_a_px4_1_15_log_has_our_layouts_of_the_1_15_definitions() -> None:
    """The field list PX4's logger wrote for a topic is its C struct; where the 1.15 definition has
    exactly those fields and types, our layout of it must be that list, padding included."""
    if not EVENTS_LOG.is_file():
        missing("the PX4 1.15 test log")
    ulog = ULog(str(EVENTS_LOG), message_name_filter_list=[])
    assert ulog.msg_info_dict["ver_sw_release"] >> 16 == 0x010F  # v1.15
    code, data, err = run_ir(CORPUS / "1.15")
    assert code == 0, err
    by_topic = {topic: m for m in data["messages"] for topic in m["uorb"]["topics"]}
    c_types = {"int8": "int8_t", "int16": "int16_t", "int32": "int32_t", "int64": "int64_t", "uint8": "uint8_t",
               "uint16": "uint16_t", "uint32": "uint32_t", "uint64": "uint64_t", "float32": "float",
               "float64": "double", "bool": "bool", "char": "char"}  # fmt: skip
    compared = 0
    for topic, fmt in ulog.message_formats.items():
        message = by_topic.get(topic)
        if message is None:
            continue
        ours = [_log_field(message, slot, c_types) for slot in message["uorb"]["layout"]]
        if sorted(ours) != sorted(fmt.fields):
            continue  # this build's definition differs from the release's
        compared += 1
        assert ours == list(fmt.fields), topic
    assert compared >= 80  # of the log's 105 formats, 86 are defined identically in 1.15


def _log_field(message: dict[str, Any], slot: dict[str, Any], c_types: dict[str, str]) -> tuple[str, int, str]:
    if slot["field"] is None:
        return ("uint8_t", slot["size"], slot["name"])
    ftype = next(f["type"] for f in message["fields"] if f["name"] == slot["field"])
    if ftype["form"] == "string":
        return ("char", ftype["capacity"], slot["name"])
    count = 0
    if ftype["form"] == "array":
        count, ftype = ftype["capacity"], ftype["element"]
    if ftype["form"] == "composite":
        short = ftype["name"].rsplit(".", 1)[-1]
        return (re.sub(r"(?<!^)(?=[A-Z])", "_", short).lower(), count, slot["name"])
    return (c_types[ftype["name"]], count, slot["name"])

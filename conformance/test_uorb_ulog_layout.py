"""Our PX4 struct layout against the layouts PX4 itself wrote into real ULog files.

The PX4 logger stores, for every topic (and every struct nested in one), the field list of the
C struct PX4's generator emitted: fields sorted by element size with ``_paddingN`` bytes. For
each such format we write a .msg holding the same fields in a scrambled order (same-size fields
keep their relative order, since PX4's sort is stable and that order is all a log can tell us),
run our frontend on the directory, and demand PX4's exact order, padding and offsets back.
"""

from __future__ import annotations

from itertools import zip_longest
from pathlib import Path

import pytest
from pyulog import ULog
from shared_data import REAL_LOGS, missing

from codegen.frontends import uorb
from codegen.ir import ArrayType, CompositeType, PrimitiveKind, PrimitiveType, Schema, StringType

DATA = REAL_LOGS
LOGS = ("sample_log_small.ulg", "sample_px4_events.ulg")
SCHEMAS = Path(__file__).resolve().parents[1] / "schemas" / "uorb"

# ULog C type -> (uORB .msg type, bytes)
C_TYPES = {
    "int8_t": ("int8", 1), "uint8_t": ("uint8", 1), "int16_t": ("int16", 2), "uint16_t": ("uint16", 2),
    "int32_t": ("int32", 4), "uint32_t": ("uint32", 4), "int64_t": ("int64", 8), "uint64_t": ("uint64", 8),
    "float": ("float32", 4), "double": ("float64", 8), "bool": ("bool", 1), "char": ("char", 1),
}  # fmt: skip
LogField = tuple[str, int, str]  # (C type or nested format name, array size or 0, name)


def camel(format_name: str) -> str:
    """File/type name for a log format: ``position_setpoint`` -> ``PositionSetpoint``."""
    return "".join(part[:1].upper() + part[1:] for part in format_name.split("_"))


def scrambled(fields: list[LogField]) -> list[LogField]:
    """Deal the fields round-robin from their size groups, smallest elements first: not PX4's
    order whenever there are two groups, yet each group keeps its order."""
    groups: dict[int, list[LogField]] = {}
    for f in fields:
        groups.setdefault(C_TYPES[f[0]][1] if f[0] in C_TYPES else 0, []).append(f)
    ordered = [groups[size] for size in sorted(groups, key=lambda s: (s != 0, s))]  # nested first
    return [f for row in zip_longest(*ordered) for f in row if f is not None]


def msg_text(fields: list[LogField]) -> str:
    lines = ["# Rebuilt from a ULog format definition", ""]
    for ctype, count, name in fields:
        base = C_TYPES[ctype][0] if ctype in C_TYPES else camel(ctype)
        lines.append(f"{base}{f'[{count}]' if count else ''} {name}")
    return "\n".join(lines) + "\n"


def log_offsets(fmt: str, formats: dict[str, list[LogField]], sizes: dict[str, int]) -> list[tuple[str, int, int]]:
    """(name, offset, size) of every field the log lists, offsets by plain accumulation."""
    out, offset = [], 0
    for ctype, count, name in formats[fmt]:
        element = C_TYPES[ctype][1] if ctype in C_TYPES else struct_size(ctype, formats, sizes)
        out.append((name, offset, element * max(count, 1)))
        offset += element * max(count, 1)
    return out


def struct_size(fmt: str, formats: dict[str, list[LogField]], sizes: dict[str, int]) -> int:
    if fmt not in sizes:
        sizes[fmt] = sum(size for _, _, size in log_offsets(fmt, formats, sizes))
    return sizes[fmt]


def our_fields(schema: Schema, fmt: str, names: dict[str, str]) -> list[LogField]:
    """Our layout of one message, spelled as the ULog format would list it."""
    message = schema.message(f"uorb.{camel(fmt)}")
    assert message.uorb is not None
    out: list[LogField] = []
    for slot in message.uorb.layout:
        if slot.field is None:
            out.append(("uint8_t", slot.size, slot.name))
            continue
        declared = message.field(slot.field).type
        element, count = declared, 0
        if isinstance(declared, StringType):  # char[N]
            element, count = PrimitiveType(PrimitiveKind.CHAR, 8), declared.capacity or 0
        elif isinstance(declared, ArrayType):
            element, count = declared.element, declared.capacity or 0
        if isinstance(element, CompositeType):
            out.append((names[element.name], count, slot.name))
        else:
            assert isinstance(element, PrimitiveType)
            ctype = next(c for c, (t, _) in C_TYPES.items() if t == element.name)
            out.append((ctype, count, slot.name))
    return out


@pytest.fixture(scope="module", params=LOGS)
def log_formats(request: pytest.FixtureRequest) -> tuple[str, dict[str, list[LogField]]]:
    if not (DATA / request.param).is_file():
        missing(f"test log {request.param}")
    ulog = ULog(str(DATA / request.param), message_name_filter_list=[])  # formats only, no data
    return request.param, {name: list(fmt.fields) for name, fmt in ulog.message_formats.items()}


def test_every_log_format_matches_our_layout(
    log_formats: tuple[str, dict[str, list[LogField]]], tmp_path: Path
) -> None:
    log_name, formats = log_formats
    # Every format here is expressible: all types are uORB builtins or other formats of the same
    # log, and each has the uint64 timestamp PX4 requires. Fail loudly if a future log is not.
    unknown = {c for fields in formats.values() for c, _, _ in fields if c not in C_TYPES and c not in formats}
    assert not unknown, f"{log_name}: types neither builtin nor a logged format: {unknown}"
    names = {f"uorb.{camel(fmt)}": fmt for fmt in formats}
    assert len(names) == len(formats), "two formats map to one .msg file name"
    scrambled_count = 0
    for fmt, fields in formats.items():
        real = [f for f in fields if not f[2].startswith("_padding")]
        order = scrambled(real)
        scrambled_count += order != real
        (tmp_path / f"{camel(fmt)}.msg").write_text(msg_text(order), encoding="utf-8")
    assert scrambled_count > len(formats) // 2, "most inputs must not already be in PX4's order"

    schema = uorb.parse_dir(tmp_path)
    assert len(schema.messages) == len(formats)
    sizes: dict[str, int] = {}
    mismatches = []
    for fmt, fields in sorted(formats.items()):
        message = schema.message(f"uorb.{camel(fmt)}")
        assert message.uorb is not None
        ours = our_fields(schema, fmt, names)
        offsets = [(s.name, s.offset, s.size) for s in message.uorb.layout]
        if ours != fields or offsets != log_offsets(fmt, formats, sizes):
            mismatches.append(f"{fmt}:\n  log  {fields}\n  ours {ours}")
        elif message.uorb.struct_size != struct_size(fmt, formats, sizes):
            mismatches.append(f"{fmt}: size {message.uorb.struct_size} != {struct_size(fmt, formats, sizes)}")
    assert not mismatches, f"{log_name}: {len(mismatches)} of {len(formats)} formats differ\n" + "\n".join(mismatches)


def test_logs_exercise_nesting_and_padding(log_formats: tuple[str, dict[str, list[LogField]]]) -> None:
    """The comparison above means something: nested structs, inner and trailing padding occur."""
    _, formats = log_formats
    fields = [f for fs in formats.values() for f in fs]
    assert any(c not in C_TYPES for c, _, _ in fields)
    assert any(f[-1][2].startswith("_padding") for f in formats.values())
    assert any(name.startswith("_padding") for fs in formats.values() for _, _, name in fs[:-1])


# PX4's generated header for msg/versioned/BatteryStatus.msg (MESSAGE_VERSION 1), as published in
# a PX4 build tree (uORB/topics/battery_status.h): member order of struct battery_status_s.
PX4_BATTERY_STATUS_V1_ORDER = (
    "timestamp",
    "voltage_v", "current_a", "current_average_a", "discharged_mah", "remaining", "scale", "time_remaining_s",
    "temperature", "voltage_cell_v", "max_cell_voltage_delta", "full_charge_capacity_wh", "remaining_capacity_wh",
    "nominal_voltage", "internal_resistance_estimate", "ocv_estimate", "ocv_estimate_filtered",
    "volt_based_soc_estimate", "voltage_prediction", "prediction_error", "estimation_covariance_norm",
    "capacity", "cycle_count", "average_time_to_empty", "manufacture_date", "state_of_health", "max_error",
    "interface_error", "faults", "over_discharge_count",
    "connected", "cell_count", "source", "priority", "id", "is_powering_off", "is_required", "warning",
    "_padding0",
)  # fmt: skip


def test_battery_status_layouts_match_px4() -> None:
    schema = uorb.parse_dir(SCHEMAS)
    v1 = schema.message("uorb.BatteryStatus").uorb
    v0 = schema.message("uorb.BatteryStatusV0").uorb
    assert v1 is not None and v0 is not None
    assert tuple(s.name for s in v1.layout) == PX4_BATTERY_STATUS_V1_ORDER
    assert (v1.layout[-1].offset, v1.layout[-1].size, v1.struct_size) == (166, 2, 168)  # uint8_t _padding0[2]
    # V0 has serial_number too: one more uint16 after average_time_to_empty fills the 2 bytes.
    v0_order = list(PX4_BATTERY_STATUS_V1_ORDER[:-1])
    v0_order.insert(v0_order.index("average_time_to_empty") + 1, "serial_number")
    assert [s.name for s in v0.layout] == v0_order
    assert v0.struct_size == 168 and all(s.field is not None for s in v0.layout)
    offsets = {s.name: (s.offset, s.size) for s in v0.layout}
    # 8 timestamp + 8 floats = 40; cell voltages float[14]; 20 uint16 bytes from 140; 8 bytes of uint8/bool
    assert offsets["voltage_cell_v"] == (40, 56)
    assert offsets["capacity"] == (140, 2) and offsets["connected"] == (160, 1) and offsets["warning"] == (167, 1)

"""The spellings PX4's own message files use that a strict reader would refuse: pi and words in a
range, '@invalid 0' on a char array, bare frame tags, a range without '@' and an enum whose
constants use another prefix. Each line here is quoted from a PX4 .msg file (the file is named)."""

from __future__ import annotations

import math
import struct
from pathlib import Path

import pytest

from codegen.errors import SchemaError
from codegen.frontends import uorb
from codegen.ir import Range, Schema, Sentinel, StringType

HEAD = "uint64 timestamp # [us] Time since system start\n"
F32_PI = struct.unpack("<f", struct.pack("<f", math.pi))[0]  # C's M_PI_F


def load(tmp_path: Path, body: str, name: str = "Sample") -> Schema:
    (tmp_path / f"{name}.msg").write_text(HEAD + body, encoding="utf-8")
    return uorb.parse_dir(tmp_path)


def test_pi_bounds_are_pi_rounded_outward_for_float32(tmp_path: Path) -> None:
    schema = load(
        tmp_path,
        "float32 course # [rad] [@range -pi, pi] [@frame NED] Course setpoint\n"  # FixedWingLateralSetpoint
        "float32 yaw # [rad] [@range -pi,pi] Yaw\n"  # RoverPositionSetpoint
        "float64 heading # [rad] [@range 0, 2*pi] Heading\nfloat32 half # [rad] [@range -pi/2, pi/2]\n",
    )
    m = schema.message("uorb.Sample")
    assert m.field("course").range == Range(-F32_PI, F32_PI) and F32_PI > math.pi
    assert m.field("course").frame == "NED" and m.field("course").doc == "Course setpoint"
    assert m.field("yaw").range == Range(-F32_PI, F32_PI)
    assert m.field("heading").range == Range(0, 2 * math.pi)  # a float64 bound is pi itself
    half = m.field("half").range
    assert half is not None and half.maximum == struct.unpack("<f", struct.pack("<f", math.pi / 2))[0]
    assert ("range", "-pi, pi") in m.field("course").annotations  # what the source wrote is kept
    assert schema.warnings == ()


def test_words_in_a_range_become_doc_text(tmp_path: Path) -> None:
    schema = load(
        tmp_path,
        "float32 normalized_steering_setpoint # [-] [@range -1 (Left), 1 (Right)] Normalized steering setpoint\n"
        "float32 speed_body_x # [m/s] [@range -inf (Backwards), inf (Forwards)] Speed setpoint\n",
    )
    steering = schema.message("uorb.Sample").field("normalized_steering_setpoint")
    assert steering.range == Range(-1, 1)
    assert steering.doc == "Normalized steering setpoint (-1: Left; 1: Right)"
    speed = schema.message("uorb.Sample").field("speed_body_x")
    assert speed.range == Range(-math.inf, math.inf) and speed.doc.endswith("(-inf: Backwards; inf: Forwards)")


def test_invalid_zero_on_a_char_array_is_the_empty_string(tmp_path: Path) -> None:
    schema = load(
        tmp_path,
        "uint8 id # Must match the id in the battery_status message for the same battery\n"  # BatteryInfo
        "char[32] serial_number # [@invalid 0 All bytes] Serial number of the battery pack in ASCII characters\n"
        "char[24] firmware_version  # [-] [@invalid empty if not available] Firmware version.\n",  # DeviceInformation
    )
    m = schema.message("uorb.Sample")
    serial = m.field("serial_number")
    assert serial.type == StringType(32) and serial.invalid == Sentinel(0, "0", per_element=True)
    assert serial.doc == "Serial number of the battery pack in ASCII characters"
    assert m.field("firmware_version").invalid == Sentinel(0, "empty", per_element=True)
    assert [(w.location.line, w.kind) for w in schema.warnings] == [(4, "invalid-value")]


def test_a_frame_written_as_a_unit_is_the_frame(tmp_path: Path) -> None:
    schema = load(tmp_path, "float32 lateral_acceleration_setpoint    # [m/s^2] [FRD] resultant lateral acceleration\n")
    f = schema.message("uorb.Sample").field("lateral_acceleration_setpoint")
    assert (f.unit_text, f.frame, f.doc) == ("m/s^2", "FRD", "resultant lateral acceleration")
    (warning,) = schema.warnings
    assert str(warning).startswith("Sample.msg:2: warning: read '[FRD]' as the frame '[@frame FRD]'")


def test_a_range_without_at_is_read_with_a_warning(tmp_path: Path) -> None:
    schema = load(tmp_path, "float32 speed   # [m/s] [-inf, inf] Speed setpoint (Backwards driving if negative)\n")
    f = schema.message("uorb.Sample").field("speed")  # PX4 1.16 DifferentialVelocitySetpoint
    assert (f.unit_text, f.range) == ("m/s", Range(-math.inf, math.inf))
    assert [(w.location.line, w.kind) for w in schema.warnings] == [(2, "range-without-at")]


def test_an_enum_whose_constants_have_another_prefix_warns(tmp_path: Path) -> None:
    schema = load(
        tmp_path,
        "uint8 fusion_status # [@enum VTE_FUSION_STATUS] Fusion status code\n"  # VteAidSource1d
        "uint8 STATUS_IDLE = 0 # No fusion attempted yet\nuint8 STATUS_FUSED_CURRENT = 1 # Fused immediately\n",
    )
    m = schema.message("uorb.Sample")
    f = m.field("fusion_status")
    assert f.enums == () and ("enum", "VTE_FUSION_STATUS") in f.annotations
    assert m.enums == () and [c.name for c in m.constants] == ["STATUS_IDLE", "STATUS_FUSED_CURRENT"]
    (warning,) = schema.warnings
    assert (warning.location.file, warning.location.line, warning.kind) == ("Sample.msg", 2, "enum-prefix")
    assert "names no constant VTE_FUSION_STATUS_*" in warning.message and "STATUS_" in warning.message


@pytest.mark.parametrize(
    ("body", "expected"),
    [
        ("char[8] name # [@invalid 7]\n", "expected '[@invalid 0]' (all bytes zero: an empty string) on a char array"),
        ("float32 x # [@range -pi, tau]\n", "expected '[@range <min>, <max>]' with numbers or multiples of pi"),
        ("float32 x # [@range (Left), 1]\n", "expected '[@range <min>, <max>]'"),
        ("float32 x # [@range pi, -pi]\n", "expected min <= max"),
        ("float32 x # [m] [s]\n", "expected one unit, got '[m]' and '[s]'"),
        ("float32 x # [FRD] [@frame NED]\n", "expected one '[@frame ...]' per field"),
    ],
)
def test_what_stays_an_error(tmp_path: Path, body: str, expected: str) -> None:
    (tmp_path / "Sample.msg").write_text(HEAD + body, encoding="utf-8")
    with pytest.raises(SchemaError) as info:
        uorb.parse_dir(tmp_path)
    assert (info.value.file, info.value.line) == ("Sample.msg", 2)
    assert expected in info.value.message

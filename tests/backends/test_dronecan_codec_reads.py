"""The generated DroneCAN BatteryInfo codec as a reviewer reads it (issue 29): a few lines per field, one
encoding and one decoding (the head packed and read back in one place each), its enum written once."""

from __future__ import annotations

import re

from conftest import ROOT

SOURCE = ROOT / "generated" / "dronecan" / "uavcan" / "equipment" / "power.py"
FIELDS = 14  # BatteryInfo's fields, model_name included


def _battery_info() -> tuple[str, str]:
    """(the module-level lines of BatteryInfo's codec, the class's codec from its layout comment to validate)."""
    text = SOURCE.read_text(encoding="utf-8")
    constants = "\n".join(
        block
        for block in re.split(r"\n(?=\S)", text)
        if re.match(r"(# .*\n)*_BATTERY_INFO_(FLOAT32_BITS|ENCODE_STRUCT|DECODE_STRUCT|FIELD_ENDS)\b", block)
    )
    body = text[text.index("class BatteryInfo:") :]
    body = body[body.index("# Wire layout") : body.index("    def validate(")]
    return constants, body


def test_at_most_twelve_lines_per_field() -> None:
    constants, body = _battery_info()
    lines = [line for line in (constants + "\n" + body).splitlines() if line.strip()]
    assert len(lines) <= 12 * FIELDS, len(lines) / FIELDS


def test_one_packing_and_one_reading_of_the_head() -> None:
    _, body = _battery_info()
    assert body.count("_BATTERY_INFO_ENCODE_STRUCT.pack(") == 1
    assert body.count("_BATTERY_INFO_DECODE_STRUCT.unpack_from(") == 1
    assert "._dc_from_head(" in body.split("def _dc_get(")[1]  # the bit reader starts from the same reading


def test_each_float16_has_no_inlined_cast() -> None:
    _, body = _battery_info()
    assert "f16_saturated" not in body and "65504.0" not in body  # the runtime's float32_bits casts
    assert body.count("_dc.f16bits_saturated(") == 7  # each half is cut, the uncommon ones by the runtime


def test_enum_entries_are_not_class_constants() -> None:
    text = SOURCE.read_text(encoding="utf-8")
    assert "class BatteryInfoStatusFlag(_enum.IntFlag):" in text and "    IN_USE = 1\n" in text
    assert "STATUS_FLAG_IN_USE: _ClassVar" not in text
    assert "STATE_OF_HEALTH_UNKNOWN: _ClassVar[int] = 127" in text  # a constant in no enum stays

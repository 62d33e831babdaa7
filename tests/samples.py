"""Schemas the tests build by hand: a hostile one (names and docs that try to break the generated
code), a MAVLink dialect with every kind of field, and uORB messages nesting each other. The backend
tests use them, and tests/test_typing.py type-checks the packages generated from them."""

from __future__ import annotations

import math
from pathlib import Path

from codegen.ir import (
    ArrayType,
    CompositeType,
    Constant,
    DevicetreeInfo,
    DronecanInfo,
    DronecanKind,
    EnumDef,
    EnumEntry,
    EnumKind,
    Field,
    Location,
    Message,
    PrimitiveKind,
    PrimitiveType,
    Range,
    Schema,
    Sentinel,
    SourceFormat,
    StringType,
    units,
)

L = Location("hostile.msg", 3)
U8 = PrimitiveType(PrimitiveKind.UINT, 8)
F32 = PrimitiveType(PrimitiveKind.FLOAT, 32)
EVIL = '""" + __import__("os").system("echo pwned") + """ \\ \' \x00 \r # {{ x }} {% if %}'


def _dronecan(name: str) -> DronecanInfo:
    return DronecanInfo(name, None, 1, DronecanKind.MESSAGE, False, 8, 8, 8, 8, "")


def hostile_schema() -> Schema:
    inner = Message(
        "In", "dronecan.ns.In", SourceFormat.DRONECAN, L, EVIL, (Field("v", U8, L),), dronecan=_dronecan("ns.In")
    )
    weird = Message(
        "class",
        "uorb.class",
        SourceFormat.UORB,
        L,
        EVIL,
        (
            Field("class", U8, L, doc=EVIL, unit=units.opaque(EVIL), unit_text=EVIL),
            Field("to_dict", F32, L, invalid=Sentinel(math.nan, "NaN"), range=Range(0, None)),
            Field("1st", ArrayType(F32, 3, False), L, invalid=Sentinel(0, "0", per_element=True)),
            Field("a b", StringType(8), L, default=EVIL),
            Field("QUALIFIED_NAME", PrimitiveType(PrimitiveKind.INT, 16), L, invalid=Sentinel(32767, "INT16_MAX")),
            Field("", PrimitiveType(PrimitiveKind.VOID, 3), L),
        ),
        constants=(
            Constant("class", U8, 1),
            Constant("S", StringType(), EVIL),
            Constant("E_A", U8, 0),
            Constant("E_B", U8, 1),
        ),
        enums=(EnumDef("uorb.class.E", EnumKind.VALUE, (EnumEntry("E_A", 0, EVIL), EnumEntry("E_B", 1)), EVIL),),
    )
    outer = Message(
        "Out",
        "dronecan.other.Out",
        SourceFormat.DRONECAN,
        L,
        "",
        (
            Field("inner", CompositeType("dronecan.ns.In"), L),
            Field("many", ArrayType(CompositeType("dronecan.ns.In"), 2, False), L),
        ),
        dronecan=_dronecan("other.Out"),
    )
    dt = Message(
        "battery",
        "devicetree.power.supply.battery",
        SourceFormat.DEVICETREE,
        L,
        "",
        (
            Field("compatible", StringType(), L, const="simple-battery", required=True),
            Field("voltage-min-design-microvolt", PrimitiveType(PrimitiveKind.UINT, 32), L, unit=units.unit("uV")),
            Field(
                "^t-[0-9]+$",
                ArrayType(ArrayType(PrimitiveType(PrimitiveKind.UINT, 32), 2, False), None, True),
                L,
                pattern="^t-[0-9]+$",
            ),
        ),
        devicetree=DevicetreeInfo("x", "t", ("simple-battery",), ("compatible",), False),
    )
    return Schema((outer, inner, weird, dt))


def clashing_schema() -> Schema:
    """Names that clash with what generated code uses (issue 10): types named like the typing names and
    builtins it needs, members named like its modules, builtins and classes, an enum entry ``mro``."""
    fields = tuple(
        Field(n, U8, L) for n in ("dataclasses", "struct", "math", "enum", "int", "float", "str", "bool", "Any")
    )
    kinds = EnumDef("uorb.ClassVar.KIND", EnumKind.VALUE, tuple(EnumEntry(f"KIND_{n}", i) for i, n in enumerate(
        ("mro", "name", "value", "real", "to_bytes")
    )))  # fmt: skip
    classvar = Message(
        "ClassVar",
        "uorb.ClassVar",
        SourceFormat.UORB,
        L,
        "",
        (*fields, Field("kind", U8, L, enums=("uorb.ClassVar.KIND",))),
        constants=(Constant("dataclasses", U8, 1), Constant("QUALIFIED_NAME", U8, 2), Constant("ClassVar", U8, 3)),
        enums=(kinds,),
    )
    seven = Constant("K", U8, 7)
    later = [
        Message(n, f"uorb.{n}", SourceFormat.UORB, L, "", (Field("x", U8, L), Field(n, U8, L)), constants=(seven,))
        for n in ("Any", "Mapping", "ValueError", "Struct")
    ]
    inner = Message(
        "Inner",
        "dronecan.ns.Inner",
        SourceFormat.DRONECAN,
        L,
        "",
        (Field("Outer", U8, L),),
        dronecan=_dronecan("ns.Inner"),
    )
    outer = Message(
        "Outer", "dronecan.ns.Outer", SourceFormat.DRONECAN, L, "",
        (Field("Inner", CompositeType("dronecan.ns.Inner"), L), Field("Outer", F32, L), Field("float", F32, L)),
        dronecan=_dronecan("ns.Outer"),
    )  # fmt: skip
    return Schema((classvar, *later, inner, outer))


FIELDS = """
<field type="uint64_t" name="time_usec">t</field>
<field type="char[8]" name="label">l</field>
<field type="uint8_t[4]" name="raw">r</field>
<field type="int8_t[3]" name="deltas">d</field>
<field type="double" name="ratio">x</field>
<field type="char" name="grade">g</field>
<extensions/>
<field type="float" name="extra">e</field>
"""


def mavlink_thing_xml(tmp_path: Path, fields: str = FIELDS, msg_id: int = 300, name: str = "THING") -> Path:
    path = tmp_path / "t.xml"
    path.write_text(
        f'<?xml version="1.0"?>\n<mavlink>\n<messages>\n<message id="{msg_id}" name="{name}">\n'
        f"<description>d</description>\n{fields}</message>\n</messages>\n</mavlink>\n",
        encoding="utf-8",
    )
    return path


NESTED = {
    "Inner.msg": "uint64 timestamp\nfloat32 x\nuint8 flag\nchar[5] tag\nint16[3] v\n",
    "Outer.msg": (
        "uint64 timestamp\nInner one\nInner[2] many\nuint8[4] raw\nbool ok\nchar c\n"
        "float64 d\nint8 s8\nuint32 u32\nint64 i64\n"
    ),
}

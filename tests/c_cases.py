"""The C library's replay, written by the Python side at test time: every record of the conformance
vectors (``battgen vectors``) and seeded random records (``rust_cases``: the same records the Rust
crate replays) as C initialisers, with what the generated Python package makes of each -- MAVLink 2
payload, frames (plain, signed, MAVLink 1), uORB struct, DroneCAN payload with and without the tail
array optimisation, decoded values and validator problems.

The C harness prints, case by case, what the C library makes of the same value and the same bytes;
the test compares those lines with :func:`expected_lines` (floats by their bits, NaN as ``nan``,
so -0.0 and float16 rounding show). Nothing here is committed to the library."""

from __future__ import annotations

import math
import random
import struct
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any

from rust_cases import FIELD_RULES, Unrepresentable, random_records, vector_records

from codegen.apps.schemas.package import bundled_schemas
from codegen.backends.c.types import ident, scalar, type_name
from codegen.frontends.loader import load
from codegen.ir import ArrayType, CompositeType, FieldType, Message, PrimitiveKind, PrimitiveType, Schema, StringType

# the ids of the bundled cross-field rules, which the C validators check
CROSS_RULES = frozenset("cross-field:" + r.id for r in load([bundled_schemas()]).rules)
SIGNATURE = bytes(range(13))  # the signed frames' signature block (skipped by both decoders)


# --- values as C initialisers ------------------------------------------------------------------


def _f32(value: object, exact: bool) -> str:
    if not isinstance(value, int | float) or isinstance(value, bool):
        raise Unrepresentable(value)
    try:
        packed = struct.pack("<f", value)
    except OverflowError:
        raise Unrepresentable(value) from None
    back = struct.unpack("<f", packed)[0]
    bits = int.from_bytes(packed, "little")
    if math.isnan(back):
        if bits & 0x7FFFFFFF != 0x7FC00000:
            raise Unrepresentable(value)  # a NaN payload the C NAN macro does not spell
        return "-NAN" if bits >> 31 else "NAN"
    if exact and back != value:
        raise Unrepresentable(value)
    if math.isinf(back):
        return "-INFINITY" if back < 0 else "INFINITY"
    return float(back).hex() + "f"


def _f64(value: object) -> str:
    if not isinstance(value, int | float) or isinstance(value, bool):
        raise Unrepresentable(value)
    v = float(value)
    if math.isnan(v):
        bits = struct.unpack("<Q", struct.pack("<d", v))[0]
        if bits & 0x7FFFFFFFFFFFFFFF != 0x7FF8000000000000:
            raise Unrepresentable(value)
        return "-(double)NAN" if bits >> 63 else "(double)NAN"
    if math.isinf(v):
        return "-(double)INFINITY" if v < 0 else "(double)INFINITY"
    return v.hex()


def _int(t: PrimitiveType, value: object) -> str:
    c = scalar(t)
    if isinstance(value, bool) or not isinstance(value, int):
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        else:
            raise Unrepresentable(value)
    bits = int(c.removeprefix("u").removeprefix("int")[:-2])
    signed = not c.startswith("u")
    low, high = (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if signed else (0, (1 << bits) - 1)
    if not low <= value <= high:
        raise Unrepresentable(value)
    if bits == 64:
        if signed and value == low:
            return "(-9223372036854775807LL - 1)"
        return f"{value}{'LL' if signed else 'ULL'}"
    if bits == 32:
        return f"{value}{'L' if signed else 'UL'}"
    return str(value)


def _primitive(t: PrimitiveType, value: object, exact: bool) -> str:
    if t.kind is PrimitiveKind.BOOL:
        if value not in (True, False, 0, 1):
            raise Unrepresentable(value)
        return "true" if value else "false"
    if t.kind is PrimitiveKind.CHAR:
        raw = value.encode("utf-8") if isinstance(value, str) else bytes([int(value)])  # type: ignore[call-overload]
        if raw and raw[0] > 127:
            raise Unrepresentable(value)
        return str(raw[0]) if raw else "0"
    if t.kind is PrimitiveKind.FLOAT:
        return _f64(value) if t.bits > 32 else _f32(value, exact)
    return _int(t, value)


def _chars(value: object, capacity: int) -> str:
    raw = value.encode("utf-8") if isinstance(value, str) else bytes(value) if isinstance(value, bytes | list) else None
    if raw is None or len(raw) > capacity or any(b > 127 for b in raw):
        raise Unrepresentable(value)
    return "{" + ", ".join(str(b) for b in raw) + "}" if raw else "{0}"


def _is_char_array(t: FieldType) -> bool:
    return isinstance(t, StringType) or (
        isinstance(t, ArrayType) and isinstance(t.element, PrimitiveType) and t.element.kind is PrimitiveKind.CHAR
    )


def value_init(schema: Schema, t: FieldType, value: object, exact: bool) -> tuple[str, int | None]:
    """(C initialiser, used length of a dynamic array) of ``value`` in a field of type ``t``."""
    if isinstance(t, PrimitiveType):
        return _primitive(t, value, exact), None
    if _is_char_array(t):
        assert isinstance(t, ArrayType | StringType)
        return _chars(value, t.capacity or 1), None
    if isinstance(t, CompositeType):
        if not isinstance(value, dict):
            raise Unrepresentable(value)
        return struct_init(schema, schema.message(t.name), value, exact), None
    assert isinstance(t, ArrayType)
    cap = t.capacity or 1
    if isinstance(value, bytes | bytearray):
        value = list(value)
    if not isinstance(value, list) or len(value) > cap or (not t.dynamic and len(value) != cap):
        raise Unrepresentable(value)
    items = [value_init(schema, t.element, v, exact)[0] for v in value]
    return "{" + (", ".join(items) if items else "0") + "}", len(value) if t.dynamic else None


def struct_init(schema: Schema, msg: Message, plain: Mapping[str, object], exact: bool = True) -> str:
    """The message as a C designated initialiser (fields the record leaves out at zero)."""
    parts = []
    for f in msg.fields:
        if f.is_padding or f.name not in plain:
            continue
        text, length = value_init(schema, f.type, plain[f.name], exact)
        parts.append(f".{ident(f.name)} = {text}")
        if length is not None:
            parts.append(f".{ident(f.name)}_len = {length}")
    return "{" + ", ".join(parts) + "}" if parts else "{0}"


# --- values as the harness prints them ------------------------------------------------------------


def _dump_primitive(t: PrimitiveType, v: Any) -> str:
    if t.kind is PrimitiveKind.FLOAT:
        if math.isnan(v):
            return "nan"
        if t.bits > 32:
            return f"{struct.unpack('<Q', struct.pack('<d', v))[0]:016x}"
        return f"{struct.unpack('<I', struct.pack('<f', v))[0]:08x}"
    if t.kind is PrimitiveKind.BOOL:
        return "1" if v else "0"
    if t.kind is PrimitiveKind.CHAR:
        raw = v.encode("utf-8") if isinstance(v, str) else bytes([v])
        return str(raw[0]) if raw else "0"
    return str(int(v))


def dump(schema: Schema, msg: Message, plain: Mapping[str, Any]) -> str:
    """A decoded record as the harness's ``dump_`` functions print it."""
    out = []
    for f in msg.fields:
        if f.is_padding:
            continue
        out.append(f"{f.name}={_dump_value(schema, f.type, plain[f.name])};")
    return "".join(out)


def _dump_value(schema: Schema, t: FieldType, v: Any) -> str:
    if isinstance(t, PrimitiveType):
        return _dump_primitive(t, v)
    if _is_char_array(t):
        # text is UTF-8; bytes that are not decode through surrogateescape (the MAVLink runtime)
        raw = v.encode("utf-8", "surrogateescape") if isinstance(v, str) else bytes(v)
        return raw.split(b"\0", 1)[0].hex()
    if isinstance(t, CompositeType):
        return "{" + dump(schema, schema.message(t.name), v) + "}"
    assert isinstance(t, ArrayType)
    return "[" + ",".join(_dump_value(schema, t.element, e) for e in v) + "]"


def _dump_c(schema: Schema, msg: Message) -> list[str]:
    """The harness's ``dump_<type>(const T *m)``: every field as :func:`dump` prints it."""
    lines = [f"static void dump_{type_name(msg.qualified_name)}(const {type_name(msg.qualified_name)} *m) {{"]
    for f in msg.fields:
        if f.is_padding:
            continue
        name = f"m->{ident(f.name)}"
        lines.append(f'printf("{f.name}=");')
        t = f.type
        if _is_char_array(t):
            assert isinstance(t, ArrayType | StringType)
            lines.append(f"pstr({name}, {t.capacity or 1}u);")
        elif isinstance(t, ArrayType):
            count = f"{name}_len" if t.dynamic else f"{t.capacity or 1}u"
            lines += [
                'printf("[");',
                f"for (i = 0; i < (size_t){count}; i++) {{",
                'if (i) { printf(","); }',
                _print(schema, t.element, f"{name}[i]"),
                "}",
                'printf("]");',
            ]
        else:
            lines.append(_print(schema, t, name))
        lines.append('printf(";");')
    lines.insert(1, "size_t i = 0;")
    lines.insert(2, "(void)i; (void)m;")
    return [*lines, "}"]


def _print(schema: Schema, t: FieldType, v: str) -> str:
    if isinstance(t, CompositeType):
        return f'printf("{{"); dump_{type_name(t.name)}(&{v}); printf("}}");'
    assert isinstance(t, PrimitiveType)
    if t.kind is PrimitiveKind.FLOAT:
        return f"pd({v});" if t.bits > 32 else f"pf({v});"
    if t.kind is PrimitiveKind.BOOL:
        return f'printf("%d", {v} ? 1 : 0);'
    if t.kind is PrimitiveKind.UINT or t.kind is PrimitiveKind.CHAR:
        cast = "(unsigned long long)(unsigned char)" if t.kind is PrimitiveKind.CHAR else "(unsigned long long)"
        return f'printf("%llu", {cast}{v});'
    return f'printf("%lld", (long long){v});'


# --- the cases -----------------------------------------------------------------------------------


@dataclass
class Case:
    cid: str
    given: str  # C initialiser
    exact: bool  # the initialiser holds exactly the Python record (its problems compare)
    wires: list[bytes]  # the Python encodings, as the kind orders them
    expected: list[tuple[str, str | None]]  # (tag, line) the harness must print; None: not compared
    record: dict[str, Any]  # the Python record given (its to_dict())
    seq: int  # a MAVLink frame's sequence number


@dataclass
class Replay:
    kind: str  # mavlink, uorb, dronecan
    msg: Message
    cases: list[Case] = field(default_factory=list)
    seen: set[str] = field(default_factory=set)
    skipped: int = 0
    fuzz: list[tuple[bytes, list[tuple[str, str]]]] = field(default_factory=list)  # (bytes, expected lines)


def _problems(obj: Any) -> str:
    """The problems the C validator reports too: every field rule, and the cross-field rules of
    schemas/rules (by their id) -- all of them, as the C validators check every bundled rule."""
    return ", ".join(f"{v.path} {v.rule}" for v in obj.validate() if v.rule in FIELD_RULES or v.rule in CROSS_RULES)


def _flip(frame: bytes, at: int) -> bytes:
    return frame[:at] + bytes([frame[at] ^ 0x01]) + frame[at + 1 :]


def _case(schema: Schema, replay: Replay, cid: str, obj: Any) -> Case | None:
    cls = type(obj)
    msg = replay.msg
    seq = len(replay.cases) % 256
    expected: list[tuple[str, str | None]] = []
    try:
        try:
            given, exact = struct_init(schema, msg, obj.to_dict()), True
        except Unrepresentable:
            given, exact = struct_init(schema, msg, obj.to_dict(), exact=False), False
        if replay.kind == "mavlink":
            payload = obj.encode()
            frame = obj.encode_frame(seq=seq, sysid=1, compid=1)
            signed = obj.encode_frame(seq=seq, sysid=1, compid=1, signature=SIGNATURE)
            decoded = cls.decode(payload)
            wires = [payload, frame, signed]
            expected += [("enc", payload.hex()), ("frame", frame.hex())]
            d = dump(schema, msg, decoded.to_dict())
            expected += [("dec", "0 " + d), ("fdec", "0 " + d), ("sdec", "0 " + d), ("badcrc", "8")]
            if cls.MSG_ID < 256:
                v1 = obj.encode_frame(seq=seq, sysid=1, compid=1, mavlink1=True)
                wires.append(v1)
                expected += [("v1", v1.hex()), ("v1dec", "0 " + dump(schema, msg, cls.decode_frame(v1).to_dict()))]
            else:
                wires.append(b"")
                expected += [("v1", "")]
        elif replay.kind == "uorb":
            payload = obj.encode()
            decoded = cls.decode(payload)
            wires = [payload]
            expected += [("enc", payload.hex()), ("dec", "0 " + dump(schema, msg, decoded.to_dict()))]
        else:
            payload = obj.encode()
            fd = obj.encode(tao=False)
            decoded = cls.decode(payload)
            wires = [payload, fd]
            d = dump(schema, msg, decoded.to_dict())
            expected += [("enc", "0 " + payload.hex()), ("encfd", "0 " + fd.hex())]
            expected += [("dec", "0 " + d), ("decfd", "0 " + d)]
        value = struct_init(schema, msg, decoded.to_dict())
    except (Unrepresentable, ValueError, TypeError, OverflowError, struct.error):
        replay.skipped += 1
        return None
    expected += [("prob", _problems(decoded)), ("gprob", _problems(obj) if exact else None)]
    key = given + value
    if key in replay.seen:
        return None
    replay.seen.add(key)
    return Case(cid, given, exact, wires, expected, obj.to_dict(), seq)


def _records(schema: Schema, classes: Mapping[str, Any]) -> Iterator[tuple[str, Any, dict[str, Any]]]:
    yield from vector_records()
    for qualified, cls in sorted(classes.items()):
        for cid, plain in random_records(schema, schema.message(qualified)):
            yield cid, cls, plain


def collect(schema: Schema, classes: Mapping[str, Any]) -> list[Replay]:
    """The replays of every message the vectors reach and of ``classes`` (random records)."""
    replays: dict[str, Replay] = {}
    for cid, cls, plain in _records(schema, classes):
        qualified = getattr(cls, "QUALIFIED_NAME", "")
        if qualified not in classes:
            continue
        msg = schema.message(qualified)
        kind = "mavlink" if msg.mavlink else "uorb" if msg.uorb else "dronecan"
        replay = replays.setdefault(qualified, Replay(kind, msg))
        try:
            obj = cls.from_dict(plain)
        except (ValueError, TypeError):
            replay.skipped += 1
            continue
        case = _case(schema, replay, cid, obj)
        if case is not None:
            replay.cases.append(case)
    return [replays[q] for q in sorted(replays)]


FUZZ_INPUTS = 120  # per message: random bytes and damaged encodings


def _decoded(schema: Schema, msg: Message, decode: Any, data: bytes) -> str:
    """What the harness prints of decoding ``data``: ``0`` and the values, or ``err``."""
    try:
        decoded = decode(data)
    except ValueError:  # the runtimes' DecodeError
        return "err"
    plain = decoded.to_dict()
    if msg.uorb is not None:
        # the uORB runtime reads text as UTF-8 with U+FFFD for what is not; the C keeps the bytes,
        # so text fields compare with the bytes at their offset (the other fields with Python's values)
        for slot in msg.uorb.layout:
            if slot.field is not None and _is_char_array(msg.field(slot.field).type):
                plain[slot.field] = data[slot.offset : slot.offset + slot.size]
    return "0 " + dump(schema, msg, plain)


def add_fuzz(schema: Schema, replays: list[Replay], classes: Mapping[str, Any]) -> None:
    """Seeded random bytes and damaged encodings (a byte changed, cut short, one byte more) for every
    decoder, with what the Python decoder makes of each."""
    for r in replays:
        cls = classes[r.msg.qualified_name]
        rng = random.Random("fuzz " + r.msg.qualified_name)
        longest = max(len(w) for c in r.cases for w in c.wires)
        inputs: list[bytes] = []
        for k in range(FUZZ_INPUTS):
            if k % 2 == 0 or not r.cases:
                inputs.append(bytes(rng.getrandbits(8) for _ in range(rng.randint(0, longest + 3))))
                continue
            wire = bytearray(rng.choice(r.cases).wires[0])
            damage = rng.randrange(3)
            if damage == 0 and wire:
                wire[rng.randrange(len(wire))] ^= 1 << rng.randrange(8)
            elif damage == 1:
                del wire[rng.randint(0, len(wire)) :]
            else:
                wire.append(rng.getrandbits(8))
            inputs.append(bytes(wire))
        for data in inputs:
            if r.kind == "dronecan":
                lines = [
                    ("fz", _decoded(schema, r.msg, cls.decode, data)),
                    ("fzfd", _decoded(schema, r.msg, lambda d, c=cls: c.decode(d, tao=False), data)),
                ]
            else:
                lines = [("fz", _decoded(schema, r.msg, cls.decode, data))]
            r.fuzz.append((data, lines))


def expected_lines(replays: list[Replay]) -> list[tuple[str, str | None]]:
    """(``<message>#<case> <tag>``, what follows it) of every line the harness must print."""
    fuzz: list[tuple[str, str | None]] = [
        (f"{r.msg.qualified_name}#f{k} {tag}", line)
        for r in replays
        for k, (_, lines) in enumerate(r.fuzz)
        for tag, line in lines
    ]
    return fuzz + [
        (f"{r.msg.qualified_name}#{j} {tag}", line)
        for r in replays
        for j, c in enumerate(r.cases)
        for tag, line in c.expected
    ]


# --- the harness ----------------------------------------------------------------------------------

PRELUDE = r"""/* battgen's C replay harness (written by tests/c_cases.py at test time). */
#include "battgen.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct { size_t off, len; } span;

static void hex(const uint8_t *p, size_t n) {
  size_t i;
  for (i = 0; i < n; i++) { printf("%02x", p[i]); }
}
static void pstr(const char *s, size_t cap) {
  size_t i;
  for (i = 0; i < cap && s[i] != '\0'; i++) { printf("%02x", (unsigned)(unsigned char)s[i]); }
}
static void pf(float v) {
  if (isnan(v)) { printf("nan"); } else { printf("%08lx", (unsigned long)battgen_f32_bits(v)); }
}
static void pd(double v) {
  if (isnan(v)) { printf("nan"); } else { printf("%016llx", (unsigned long long)battgen_f64_bits(v)); }
}
static void problems(const battgen_problem *p, size_t n) {
  size_t i;
  for (i = 0; i < n; i++) {
    if (i) { printf(", "); }
    const char *rule = p[i].check != NULL ? p[i].check : battgen_rule_name(p[i].rule);
    if (p[i].index >= 0) { printf("%s[%ld] %s", p[i].field, (long)p[i].index, rule); }
    else { printf("%s %s", p[i].field, rule); }
  }
}
"""


def _nested(schema: Schema, msg: Message, out: list[Message]) -> None:
    for f in msg.fields:
        t = f.type
        while isinstance(t, ArrayType):
            t = t.element
        if isinstance(t, CompositeType):
            inner = schema.message(t.name)
            _nested(schema, inner, out)
    if msg not in out:
        out.append(msg)


def _run(r: Replay) -> list[str]:
    """The harness's loop over one message's cases, printing the lines expected_lines names."""
    t = type_name(r.msg.qualified_name)
    up = t.upper()
    q = r.msg.qualified_name
    n = len(r.cases)
    lines = [
        f"static void run_{t}(void) {{",
        "size_t j;",
        f"for (j = 0; j < {n}u; j++) {{",
        f"const {t} *g = &given_{t}[j];",
        f"{t} d;",
        f"battgen_problem probs[{up}_MAX_PROBLEMS + 1u];",
        "size_t np;",
        "int e;",
        f'#define TAG(x) printf("{q}#%lu " x " ", (unsigned long)j)',
        f'#define SHOW(x, call) TAG(x); e = (call); printf("%d ", e); dump_{t}(&d); printf("\\n")',
    ]
    if r.kind == "mavlink":
        lines += [
            "uint8_t buf[BATTGEN_MAVLINK_MAX_FRAME_LENGTH + 16];",
            "size_t n;",
            "battgen_mavlink_header h, got;",
            f"const span *w = wire_{t}[j];",
            "h.seq = (uint8_t)(j % 256u); h.sysid = 1; h.compid = 1;",
            f'TAG("enc"); n = {t}_encode(g, buf); hex(buf, n); printf("\\n");',
            f'TAG("frame"); n = {t}_encode_frame(g, h, buf); hex(buf, n); printf("\\n");',
            f'SHOW("dec", {t}_decode(blob + w[0].off, w[0].len, &d));',
            f"e = {t}_decode_frame(blob + w[1].off, w[1].len, &got, &d);",
            "if (e == 0 && (got.seq != h.seq || got.sysid != 1 || got.compid != 1)) { e = 99; }",
            'SHOW("fdec", e);',
            f'SHOW("sdec", {t}_decode_frame(blob + w[2].off, w[2].len, &got, &d));',
            "memcpy(buf, blob + w[1].off, w[1].len); buf[BATTGEN_MAVLINK_HEADER_LENGTH] ^= 1u;",
            f'TAG("badcrc"); printf("%d\\n", {t}_decode_frame(buf, w[1].len, &got, &d));',
            f'TAG("v1"); n = {t}_encode_frame_v1(g, h, buf); hex(buf, n); printf("\\n");',
            "if (w[3].len) {",
            f'SHOW("v1dec", {t}_decode_frame(blob + w[3].off, w[3].len, &got, &d));',
            "}",
            f"e = {t}_decode(blob + w[0].off, w[0].len, &d); (void)e;",
        ]
    elif r.kind == "uorb":
        lines += [
            f"uint8_t buf[{up}_STRUCT_SIZE];",
            f"const span *w = wire_{t}[j];",
            "memset(buf, 0xAA, sizeof buf);",
            f'TAG("enc"); {t}_encode(g, buf); hex(buf, sizeof buf); printf("\\n");',
            f'SHOW("dec", {t}_decode(blob + w[0].off, w[0].len, &d));',
        ]
    else:
        lines += [
            f"uint8_t buf[{up}_MAX_BYTES + 1u];",
            "size_t n = 0;",
            f"const span *w = wire_{t}[j];",
            f'TAG("enc"); e = {t}_encode(g, true, buf, &n); printf("%d ", e); hex(buf, n); printf("\\n");',
            f'TAG("encfd"); e = {t}_encode(g, false, buf, &n); printf("%d ", e); hex(buf, n); printf("\\n");',
            f'SHOW("decfd", {t}_decode(blob + w[1].off, w[1].len, false, &d));',
            f'SHOW("dec", {t}_decode(blob + w[0].off, w[0].len, true, &d));',
        ]
    lines += [
        f'TAG("prob"); np = {t}_validate(&d, probs, {up}_MAX_PROBLEMS + 1u); problems(probs, np); printf("\\n");',
        f'TAG("gprob"); np = {t}_validate(g, probs, {up}_MAX_PROBLEMS + 1u); problems(probs, np); printf("\\n");',
        "#undef TAG",
        "#undef SHOW",
        "}",
        "}",
    ]
    return lines


def _fuzz_run(r: Replay) -> list[str]:
    """The harness's loop decoding one message's fuzz inputs: ``0`` and the values, or ``err``."""
    t = type_name(r.msg.qualified_name)
    q = r.msg.qualified_name
    calls = [("fz", "w.len, true, &d"), ("fzfd", "w.len, false, &d")] if r.kind == "dronecan" else [("fz", "w.len, &d")]
    lines = [
        f"static void fuzz_run_{t}(void) {{",
        "size_t k;",
        f"for (k = 0; k < {len(r.fuzz)}u; k++) {{",
        f"const span w = fuzz_{t}[k];",
        f"{t} d;",
        "/* a copy of exactly the input's bytes: a read beyond them is the sanitizer's to see */",
        "uint8_t *copy = (uint8_t *)malloc(w.len + 1u);",
        "if (copy == NULL) { exit(2); }",
        "memcpy(copy, blob + w.off, w.len);",
    ]
    for tag, args in calls:
        lines += [
            f'printf("{q}#f%lu {tag} ", (unsigned long)k);',
            f"if ({t}_decode(copy, {args}) == BATTGEN_OK) {{",
            f'printf("0 "); dump_{t}(&d); printf("\\n");',
            '} else { printf("err\\n"); }',
        ]
    return [*lines, "free(copy);", "}", "}"]


def render_harness(schema: Schema, replays: list[Replay]) -> str:
    """The harness's ``main.c``: the cases as data, a loop per message, ``main`` running them all."""
    blob = bytearray()
    out = [PRELUDE]
    dumped: list[Message] = []
    for r in replays:
        _nested(schema, r.msg, dumped)
    for m in dumped:
        out += _dump_c(schema, m)
    tables: list[str] = []
    for r in replays:
        t = type_name(r.msg.qualified_name)
        tables.append(f"static const {t} given_{t}[] = {{")
        tables += [f"{c.given}, /* {c.cid} */" for c in r.cases]
        tables.append("};")
        width = len(r.cases[0].wires)
        rows = []
        for c in r.cases:
            spans = []
            for w in c.wires:
                spans.append(f"{{{len(blob)}u, {len(w)}u}}")
                blob += w
            rows.append("{" + ", ".join(spans) + "},")
        tables += [f"static const span wire_{t}[][{width}] = {{", *rows, "};"]
    for r in replays:
        t = type_name(r.msg.qualified_name)
        spans = []
        for data, _ in r.fuzz:
            spans.append(f"{{{len(blob)}u, {len(data)}u}},")
            blob += data
        tables += [f"static const span fuzz_{t}[] = {{", *(spans or ["{0u, 0u},"]), "};"]
    out.append("static const uint8_t blob[] = {" + ", ".join(str(b) for b in blob) + (", 0" if not blob else "") + "};")
    out += tables
    for r in replays:
        out += _run(r)
    for r in replays:
        out += _fuzz_run(r)
    out.append("int main(void) {")
    out.append("(void)pd;  /* the bundled schemas have no double field */")
    out += [f"fuzz_run_{type_name(r.msg.qualified_name)}();" for r in replays]
    out += [f"run_{type_name(r.msg.qualified_name)}();" for r in replays]
    out += ["return 0;", "}", ""]
    return "\n".join(out)

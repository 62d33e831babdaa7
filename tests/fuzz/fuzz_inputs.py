"""Hypothesis strategies for the data fuzzers: random bytes, mutations of valid seeds, and documents
built from the messages' own field names (so inputs reach from_dict and the validators, not just the parser).
"""

from __future__ import annotations

import json
import random

import yaml
from hypothesis import strategies as st

# Byte strings that once broke something, or sit on a limit: spliced into seeds by the mutator.
TOKENS = (
    b"9" * 4400,  # more digits than Python converts
    b"-" + b"9" * 40,
    b"1e999",
    b"NaN",
    b"-Infinity",
    b"[" * 3000,
    b'{"a":' * 1000,
    b"&a [*a, *a]",
    b"*a",
    b'/incbin/("/dev/zero", 0, 4)',
    b'/incbin/("../../../etc/passwd")',
    b'/include/ "/etc/passwd"',
    b"\xfd",
    b"\xfe",
    b"\xff\xff\xff\xff",
    b"\x00" * 8,
    b"uint8_t[999999999999] x;",
    b"uint8_t[65535] x;",
    b"\xef\xbb\xbf",
    b"\xc3\x28",
    b"\n",
    b"\t",
    b"\r\n",
    b";",
    b"<0xffffffff>",
    b"0x" + b"f" * 40,
)

FIELD_NAMES = (
    "timestamp",
    "voltage_v",
    "current_a",
    "remaining",
    "temperature",
    "cell_count",
    "voltage_cell_v",
    "max_error",
    "warning",
    "connected",
    "faults",
    "id",
    "voltages",
    "voltages_ext",
    "current_consumed",
    "battery_remaining",
    "fault_bitmask",
    "compatible",
    "device-chemistry",
    "voltage-min-design-microvolt",
    "voltage-max-design-microvolt",
    "ocv-capacity-celsius",
    "ocv-capacity-table-0",
    "charge-full-design-microamp-hours",
    "state_of_charge_pct",
    "status_flags",
    "model_name",
)


@st.composite
def mutated(draw: st.DrawFn, seeds: list[bytes]) -> bytes:
    """A seed with a few random edits: byte changes, insertions (random or TOKENS), deletions,
    duplicated slices, truncation."""
    data = bytearray(draw(st.sampled_from(seeds)))
    for _ in range(draw(st.integers(1, 6))):
        op = draw(st.integers(0, 5))
        pos = draw(st.integers(0, len(data)))
        if op == 0 and data:
            data[min(pos, len(data) - 1)] = draw(st.integers(0, 255))
        elif op == 1:
            data[pos:pos] = draw(st.binary(min_size=1, max_size=16))
        elif op == 2:
            del data[pos : pos + draw(st.integers(1, 32))]
        elif op == 3:
            end = min(len(data), pos + draw(st.integers(1, 64)))
            data[pos:pos] = data[pos:end] * draw(st.integers(1, 8))
        elif op == 4:
            del data[pos:]
        else:
            data[pos:pos] = draw(st.sampled_from(TOKENS))
    return bytes(data)


_KEYS = st.one_of(st.sampled_from(FIELD_NAMES), st.text(max_size=8))
_LEAVES = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(2**70), 2**70),
    st.sampled_from([0, 1, -1, 14, 15, 255, 256, 65535, -(10**8), -780_000_000_000, 3200000, 100, 120]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=12),
    st.sampled_from(["NaN", "Infinity", "-Infinity", "lithium-ion", "simple-battery"]),
)
_VALUES = st.recursive(
    _LEAVES, lambda inner: st.lists(inner, max_size=16) | st.dictionaries(_KEYS, inner, max_size=6), max_leaves=40
)
_RECORD = st.dictionaries(_KEYS, _VALUES, max_size=10)
RECORDS = st.one_of(_RECORD, st.lists(_RECORD, max_size=4), _VALUES)


@st.composite
def yaml_bomb(draw: st.DrawFn) -> bytes:
    """A YAML document whose aliases expand to width**depth items (a "billion laughs")."""
    width, depth = draw(st.integers(2, 10)), draw(st.integers(1, 12))
    key = draw(st.sampled_from(FIELD_NAMES))
    parts = ["&a0 [" + ", ".join(['"lol"'] * width) + "]"]
    for level in range(1, depth):
        parts.append(f"&a{level} [" + ", ".join([f"*a{level - 1}"] * width) + "]")
    return f"{key}: [{', '.join(parts)}]\n".encode()


def document(kind: str) -> st.SearchStrategy[bytes]:
    """Structured documents of a text kind (json, jsonl, yaml)."""
    if kind == "json":
        return RECORDS.map(lambda r: json.dumps(r, allow_nan=True).encode())
    if kind == "jsonl":
        return st.lists(RECORDS, max_size=5).map(lambda rs: "\n".join(json.dumps(r) for r in rs).encode())
    return st.one_of(RECORDS.map(lambda r: yaml.safe_dump(r).encode()), yaml_bomb())


def inputs(kind: str, seeds: list[bytes]) -> st.SearchStrategy[bytes]:
    """Everything a fuzzer of one file kind draws from."""
    options = [mutated(seeds), st.binary(max_size=256)]
    if kind in ("json", "jsonl", "yaml"):
        options.append(document(kind))
    return st.one_of(*options)


def mutate(rng: random.Random, seeds: list[bytes]) -> bytes:
    """What :func:`mutated` draws, from a seeded generator instead of hypothesis: the long run's mutator (no
    shrinking, a hundred times the inputs a second; a failing input is shrunk afterwards by hand or by the
    hypothesis fuzzers)."""
    if rng.random() < 0.1:
        return rng.randbytes(rng.randrange(512))
    data = bytearray(rng.choice(seeds))
    for _ in range(rng.randint(1, 6)):
        op = rng.randrange(6)
        pos = rng.randrange(len(data) + 1)
        if op == 0 and data:
            data[min(pos, len(data) - 1)] = rng.randrange(256)
        elif op == 1:
            data[pos:pos] = rng.randbytes(rng.randint(1, 16))
        elif op == 2:
            del data[pos : pos + rng.randint(1, 32)]
        elif op == 3:
            end = min(len(data), pos + rng.randint(1, 64))
            data[pos:pos] = data[pos:end] * rng.randint(1, 8)
        elif op == 4:
            del data[pos:]
        else:
            data[pos:pos] = rng.choice(TOKENS)
    return bytes(data)

"""Fuzzing every data reader with the validator behind it: JSON, JSON Lines, YAML, .dts, .dtb, .param,
QGroundControl .params, ULog, .tlog and raw MAVLink, on mutated seeds, random bytes and (for the text
kinds) documents made of the messages' field names, YAML alias bombs included.

A reader yields records, notices and unreadable parts, or raises a located error naming the file; every
message stays short; no exception of another type escapes and no catch-all has to hide one
(tests/fuzz/targets.py ``read``).
"""

from __future__ import annotations

import pytest
from budget import fuzz_settings
from fuzz_inputs import inputs
from hypothesis import given
from hypothesis import strategies as st
from targets import SUFFIX, TARGETS, seeds


@pytest.mark.parametrize("kind", sorted(SUFFIX))
def test_fuzz_reader(kind: str) -> None:
    target = TARGETS[f"read-{kind}"]

    @fuzz_settings(ci=60)
    @given(inputs(kind, seeds(kind)))
    def run(data: bytes) -> None:
        target(data)

    run()


@fuzz_settings(ci=10)
@given(st.sampled_from(sorted(SUFFIX)))
def test_empty_input_of_every_kind(kind: str) -> None:
    TARGETS[f"read-{kind}"](b"")

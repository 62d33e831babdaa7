"""Every dialect file of current mavlink/mavlink (../shared/corpus/upstream/mavlink/, see its SOURCE.md)
read by our frontend and by pymavlink's parser (mavparse) on the same file.

pymavlink's bundled dialects lag upstream (its BATTERY_STATUS has no invalid markers on the
extension fields, it has no development.xml), so this corpus is what "reads what upstream
publishes" is measured on: message set, ids, CRC_EXTRA, wire order, lengths, field types,
units, invalid markers and enum entries must all equal mavparse's.
"""

from __future__ import annotations

import contextlib
import io
from functools import cache
from pathlib import Path
from typing import Any

import pytest
from pymavlink.generator import mavparse
from shared_data import UPSTREAM

from codegen.frontends import mavlink
from codegen.frontends.mavlink.layout import c_type
from codegen.ir import Schema

CORPUS = UPSTREAM / "mavlink"
DIALECTS = sorted(p.name for p in CORPUS.glob("*.xml"))


def _closure(path: Path) -> list[Any]:
    """The file and everything it includes, breadth first, each once (as mavgen expands them)."""
    seen: set[Path] = set()
    queue, out = [path.resolve()], []
    with contextlib.redirect_stdout(io.StringIO()):
        while queue:
            p = queue.pop(0)
            if p in seen:
                continue
            seen.add(p)
            x = mavparse.MAVXML(str(p), mavparse.PROTOCOL_2_0)
            out.append(x)
            queue.extend((p.parent / inc).resolve() for inc in x.include)
    return out


@cache
def ours(name: str) -> Schema:
    return mavlink.parse_file(CORPUS / name, root=CORPUS)


def test_corpus_is_the_whole_upstream_folder() -> None:
    assert len(DIALECTS) == 20
    assert {"common.xml", "development.xml", "all.xml", "ardupilotmega.xml", "minimal.xml"} <= set(DIALECTS)


@pytest.mark.parametrize("dialect", DIALECTS)
def test_dialect_matches_mavparse(dialect: str) -> None:
    xmls = _closure(CORPUS / dialect)
    reference = {m.name: m for x in xmls for m in x.message}
    schema = ours(dialect)
    assert sorted(m.name.removeprefix("mavlink.") for m in schema.messages) == sorted(reference)
    bad = []
    for msg in schema.messages:
        theirs = reference[msg.name.removeprefix("mavlink.")]
        info = msg.mavlink
        assert info is not None
        got = (info.msg_id, info.crc_extra, list(info.wire_order), info.base_length, info.max_length)
        want = (theirs.id, theirs.crc_extra, theirs.ordered_fieldnames, theirs.wire_min_length, theirs.wire_length)
        if got != want:
            bad.append(f"{msg.name}: ours {got} != mavparse {want}")
        for i, (f, tf) in enumerate(zip(msg.fields, theirs.fields, strict=True)):
            mine = (f.name, c_type(f.type), f.extension, f.unit_text or "", f.invalid.text if f.invalid else "")
            units = tf.units[1:-1] if tf.units else ""
            if mine != (tf.name, (tf.type, tf.array_length), i >= theirs.base_fields(), units, tf.invalid):
                bad.append(f"{msg.name}.{f.name}: {mine}")
    assert bad == []
    with contextlib.redirect_stdout(io.StringIO()):
        mavparse.merge_enums(xmls)  # as mavgen does: one enum per name over the include closure
    enums = {e.name: [(x.name, x.value) for x in e.entry if not x.end_marker] for x in xmls for e in x.enum}
    assert {e.short_name: [(x.name, x.value) for x in e.entries] for e in schema.enums} == enums


def test_every_invalid_spelling_upstream_uses_is_read() -> None:
    """The census of invalid= spellings over all.xml's closure (every dialect but test files)."""
    spellings = {f.invalid.text for m in ours("all.xml").messages for f in m.fields if f.invalid is not None}
    assert {"NaN", "NAN", "[NaN:]", "[0]", "[0,]", "0xFFFF", "-1.0", "UINT16_MIN", "MAV_LANDED_STATE_UNDEFINED"} <= (
        spellings
    )
    gcs = ours("development.xml").message("mavlink.CONTROL_STATUS").field("gcs_secondary").invalid
    assert gcs is not None and gcs.elements == (0,)  # only the first element is marked
    assert [gcs.marker_at(i) for i in range(3)] == [0, None, None]

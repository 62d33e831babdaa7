"""MAVLink array ``invalid`` markers read as upstream defines them, on upstream's own dialect files.

The MAVLink guide (mavlink/mavlink-devguide, en/guide/xml_schema.md, field ``invalid``) gives the array
forms: ``[X]``: each element holding X is invalid; ``[X:]``: *all* elements are invalid when the *first*
holds X; ``[X1,,X3,]``: by position. pymavlink's mavgen carries the attribute as text (its Ada generator
only uses it for defaults), so the guide is the reference. Checked here on the corpus
(../shared/corpus/upstream/mavlink, see its SOURCE.md): every ``[X:]`` field upstream (the covariance matrices
of common.xml and others) is read as first-decides, and its own description says the same; and on
code generated from upstream's ATT_POS_MOCAP (``covariance``, ``[NaN:]``) and BATTERY_STATUS
(``voltages``, ``[UINT16_MAX]``): ``is_known`` and ``validate`` follow each form.
"""

from __future__ import annotations

import importlib
import math
import sys
from collections.abc import Iterator
from functools import cache
from typing import Any

import pytest
from shared_data import UPSTREAM

from codegen.backends.python import naming
from codegen.backends.python.writer import generate
from codegen.frontends import mavlink
from codegen.ir import Field, Schema

CORPUS = UPSTREAM / "mavlink"
NAN = math.nan


@cache
def everything() -> Schema:
    return mavlink.parse_file(CORPUS / "all.xml", root=CORPUS)


def _array_fields() -> list[tuple[str, Field]]:
    return [
        (m.name, f)
        for m in everything().messages
        for f in m.fields
        if f.invalid is not None and f.invalid.text.startswith("[")
    ]


def test_every_first_decides_marker_upstream_is_read_as_such() -> None:
    first = [(m, f) for m, f in _array_fields() if f.invalid is not None and f.invalid.text.endswith(":]")]
    assert len(first) >= 10  # the covariance matrices of common.xml, storm32's quaternion, ...
    for name, f in first:
        assert f.invalid is not None and f.invalid.first_decides and not f.invalid.per_element, (name, f.name)
        # upstream's own prose for each such field: the first element carries the marker
        assert "first element" in " ".join(f.doc.lower().split()), (name, f.name, f.doc)


def test_every_per_element_marker_upstream_stays_per_element() -> None:
    plain = [(m, f) for m, f in _array_fields() if f.invalid is not None and "," not in f.invalid.text]
    plain = [(m, f) for m, f in plain if not f.invalid or not f.invalid.text.endswith(":]")]
    assert plain
    for name, f in plain:
        assert f.invalid is not None and f.invalid.per_element and not f.invalid.first_decides, (name, f.name)
    voltages = everything().message("mavlink.BATTERY_STATUS").field("voltages").invalid
    assert voltages is not None and (voltages.text, voltages.per_element) == ("[UINT16_MAX]", True)


@pytest.fixture(scope="module")
def classes(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    """ATT_POS_MOCAP and BATTERY_STATUS of upstream's common.xml, generated into a temporary package."""
    common = mavlink.parse_file(CORPUS / "common.xml", root=CORPUS)
    picked = tuple(common.message(f"mavlink.{n}") for n in ("ATT_POS_MOCAP", "BATTERY_STATUS"))
    out = tmp_path_factory.mktemp("mav_invalid")
    generate(Schema(messages=picked, enums=common.enums, sources=common.sources), out / "mav_invalid")
    sys.path.insert(0, str(out))
    try:
        found = {}
        for msg in picked:
            module = importlib.import_module(f"mav_invalid.{naming.module_path(msg)}")
            found[msg.name.removeprefix("mavlink.")] = getattr(module, naming.class_name(msg))
        yield found
    finally:
        sys.path.remove(str(out))
        for name in [n for n in sys.modules if n.split(".")[0] == "mav_invalid"]:
            del sys.modules[name]


def _covariance_findings(cls: Any, covariance: list[float]) -> list[str]:
    obj = cls(q=[1.0, 0.0, 0.0, 0.0], covariance=covariance)
    return [v.message for v in obj.validate() if str(v.path).startswith("covariance")]


def test_first_element_decides_for_the_whole_covariance(classes: dict[str, Any]) -> None:
    mocap = classes["ATT_POS_MOCAP"]
    unknown = mocap(q=[1.0, 0.0, 0.0, 0.0], covariance=[NAN] + [0.0] * 20)
    assert not unknown.is_known("covariance")  # per element, the zeros would have read as known data
    assert mocap(q=[1.0, 0.0, 0.0, 0.0], covariance=[0.25] * 21).is_known("covariance")
    assert mocap(q=[1.0, 0.0, 0.0, 0.0], covariance=[0.25] + [NAN] * 20).is_known("covariance")
    # what the other elements of an unknown covariance hold means nothing: nothing is reported in it ...
    assert _covariance_findings(mocap, [NAN, math.inf] + [0.0] * 19) == []
    # ... while a known covariance is checked element by element
    (finding,) = _covariance_findings(mocap, [0.25, math.inf] + [0.0] * 19)
    assert finding.startswith("covariance[1] = inf")
    meta = {f.name: f.metadata for f in mocap.__dataclass_fields__.values()}["covariance"]
    assert (meta["invalid_text"], meta["per_element"], meta["first_decides"]) == ("[NaN:]", False, True)


def test_battery_voltages_stay_per_element(classes: dict[str, Any]) -> None:
    status = classes["BATTERY_STATUS"]
    assert not status(voltages=[65535] * 10).is_known("voltages")
    assert status(voltages=[3900] + [65535] * 9).is_known("voltages")
    assert status(voltages=[65535, 3900] + [65535] * 8).is_known("voltages")  # [X]: no element speaks for all
    assert status(voltages=[65535, 3900] + [65535] * 8).validate() == []
    meta = {f.name: f.metadata for f in status.__dataclass_fields__.values()}["voltages"]
    assert (meta["per_element"], meta["first_decides"]) == (True, False)

"""The generated Cyphal codecs against pycyphal, on the classes nunavut generates (what a pycyphal user runs).

Every bundled battery and physics type (schemas/cyphal/) is compiled by ``pycyphal.dsdl.compile_all`` (nunavut
underneath) at test time; hypothesis draws values in pydsdl's form (the strategy of ``test_cyphal_codec``, which
follows pydsdl's reading of each type; the bundled types hold no text or ``byte`` arrays, so its plain data is
pycyphal's builtin form too), pycyphal builds its object from them (``update_from_builtin``) and
serializes it: our class built from the same values must give the same bytes, read pycyphal's bytes back to the
same values, and pycyphal must read our bytes back to them too.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Iterator
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st
from test_cyphal_codec import BUNDLED, OURS, SWEEP, _bundled, plain, same, values

pytest.importorskip("nunavut")
pycyphal_dsdl = pytest.importorskip("pycyphal.dsdl")


@pytest.fixture(scope="module")
def pycyphal_classes(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    """Our qualified name -> the class nunavut generates for pycyphal (``reg.udral.service.battery.Status_0_2``)."""
    out = tmp_path_factory.mktemp("pycyphal_bundled")
    roots = sorted(p for p in OURS.iterdir() if p.is_dir())
    pycyphal_dsdl.compile_all(roots, output_directory=out)
    sys.path.insert(0, str(out))
    try:
        found = {}
        for name in BUNDLED:
            module, _, short = name.removeprefix("cyphal.").rpartition(".")
            found[name] = getattr(importlib.import_module(module), short)
        yield found
    finally:
        sys.path.remove(str(out))
        for module in [m for m in sys.modules if m.split(".")[0] in {p.name for p in roots}]:
            del sys.modules[module]


def test_every_bundled_type_is_compiled(pycyphal_classes: dict[str, Any]) -> None:
    assert len(pycyphal_classes) == len(BUNDLED) == 19
    for name, cls in pycyphal_classes.items():
        ours, _ = _bundled()[name]
        assert cls._EXTENT_BYTES_ == ours.EXTENT_BYTES


@pytest.mark.parametrize("name", BUNDLED)
@SWEEP
@given(data=st.data())
def test_bundled_values_as_pycyphal(pycyphal_classes: dict[str, Any], name: str, data: st.DataObject) -> None:
    ours_cls, t = _bundled()[name]
    theirs_cls = pycyphal_classes[name]
    value = data.draw(values(t))
    theirs = pycyphal_dsdl.update_from_builtin(theirs_cls(), plain(value))
    expected = b"".join(bytes(f) for f in pycyphal_dsdl.serialize(theirs))
    ours = ours_cls.from_dict(plain(value))
    assert ours.encode() == expected
    assert same(ours_cls.decode(expected).to_dict()) == same(value)
    if name.endswith(".__0_1"):
        # nunavut names the class of the service marker ``_.0.1`` ``__0_1``, and its deserializer calls
        # ``__0_1(...)`` inside the class body, which Python's private-name mangling turns into ``_0_1__0_1``: a
        # NameError in pycyphal's reading of it, whatever the bytes (its writing, above, is sound)
        return
    back = pycyphal_dsdl.deserialize(theirs_cls, [memoryview(ours.encode())])
    assert back is not None and same(pycyphal_dsdl.to_builtin(back)) == same(plain(value))

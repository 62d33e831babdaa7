"""Random instances of flat generated uORB classes (scalars and builtin arrays), for the ULog tests that
compare our writer and reader with pyulog (test_ulog_pyulog.py, test_ulog_px4_versions.py)."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any

from hypothesis import strategies as st


def scalar(type_text: str) -> st.SearchStrategy[Any]:
    """Every value of one uORB scalar type (bool, float32, intN, uintN)."""
    if type_text == "bool":
        return st.booleans()
    if type_text == "float32":
        return st.floats(width=32)
    bits = int(type_text.lstrip("uint"))
    if type_text.startswith("uint"):
        return st.integers(0, (1 << bits) - 1)
    return st.integers(-(1 << (bits - 1)), (1 << (bits - 1)) - 1)


def instances(cls: type[Any], overrides: Mapping[str, st.SearchStrategy[Any]] | None = None) -> st.SearchStrategy[Any]:
    """Random instances of ``cls``; ``overrides`` draws the fields it names its own way."""
    fields: dict[str, st.SearchStrategy[Any]] = {}
    for f in dataclasses.fields(cls):
        base, _, count = f.metadata["type"].partition("[")
        if overrides is not None and f.name in overrides:
            fields[f.name] = overrides[f.name]
        elif count:
            n = int(count[:-1])
            fields[f.name] = st.lists(scalar(base), min_size=n, max_size=n)
        else:
            fields[f.name] = scalar(base)
    return st.builds(cls, **fields)

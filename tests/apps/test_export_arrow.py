"""The export's numpy-to-Arrow arrays (:mod:`codegen.apps.export.arrow`) are the arrays ``pa.array`` makes from the
same values and masks, refuse what its safe cast refuses, and import no pandas (which ``pa.array`` does)."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pyarrow as pa
import pytest
from conftest import ROOT

from codegen.apps.export import arrow

MASK = np.array([False, True, False, False, True])
CASES = [
    (np.array([1.5, np.nan, -0.0, np.inf, 2.0]), pa.float64()),
    (np.array([1.5, 2.5, -3.0, 0.0, 1e30], np.float32), pa.float32()),
    (np.array([0, 1, -5, 1 << 40, 7], np.int64), pa.int64()),
    (np.array([0, 1, -5, 2**31 - 1, -(2**31)], np.int64), pa.int32()),  # narrowed where every value fits
    (np.array([0, 255, 3, 4, 5], np.uint8), pa.uint8()),
    (np.array([0, 1, 65535, 4, 5], np.int64), pa.uint16()),
    (np.array([True, False, True, True, False]), pa.bool_()),
    (np.array([1_700_000_000_000_000, 0, -1, 5, 6], np.int64), pa.timestamp("us", tz="UTC")),
]


@pytest.mark.parametrize(("values", "typ"), CASES, ids=[str(t) for _, t in CASES])
@pytest.mark.parametrize("mask", [None, MASK, np.zeros(5, bool)], ids=["no mask", "mask", "nothing null"])
def test_arrays_are_what_pa_array_makes(values: np.ndarray, typ: pa.DataType, mask: np.ndarray | None) -> None:
    ours = arrow.array(values, typ, mask)
    ours.validate(full=True)
    if pa.types.is_timestamp(typ):
        expected = pa.array(values, pa.int64(), mask=mask).cast(typ)
    else:
        expected = pa.array(values, typ, mask=mask)
    assert ours.type == typ and ours.null_count == expected.null_count
    assert ours.to_pylist() == expected.to_pylist() or _same_floats(ours, expected)


def _same_floats(a: pa.Array, b: pa.Array) -> bool:
    x, y = a.to_pylist(), b.to_pylist()
    return all(p == q or (p != p and q != q) for p, q in zip(x, y, strict=True))


def test_floats_are_narrowed_as_arrow_narrows_them() -> None:
    values = np.array([16.1, 1e300, -1e300])
    assert arrow.array(values, pa.float32()).equals(pa.array(values, pa.float32()))


def test_a_slice_of_a_matrix_is_copied_contiguous() -> None:
    matrix = np.arange(12, dtype=np.float64).reshape(3, 4)
    assert arrow.array(matrix[:, 1], pa.float64()).to_pylist() == [1.0, 5.0, 9.0]


@pytest.mark.parametrize(
    ("values", "typ"),
    [
        (np.array([1, 2**31], np.int64), pa.int32()),
        (np.array([2, -1], np.int64), pa.uint32()),
        (np.array([1.0, 2.5]), pa.int64()),
        (np.array([1.0, np.nan]), pa.int64()),
    ],
)
def test_a_value_its_type_cannot_hold_is_refused_as_pa_array_refuses_it(values: np.ndarray, typ: pa.DataType) -> None:
    with pytest.raises(pa.ArrowInvalid):
        pa.array(values, typ)
    with pytest.raises(ValueError, match="does not fit the Arrow type"):
        arrow.array(values, typ)
    # where the value is null, it is not looked at (pa.array's safe cast does not look either)
    assert arrow.array(values, typ, np.array([False, True])).to_pylist() == [int(values[0]), None]


@pytest.mark.parametrize(
    ("values", "mask"),
    [
        (["a", None, "ünïcode", "", "x" * 300], None),
        (np.array(["a", None, "b"], object), np.array([False, False, True])),
        ([b"bytes", "text"], None),
        ([], None),
    ],
)
def test_strings_are_what_pa_array_makes(values: list[object], mask: np.ndarray | None) -> None:
    ours = arrow.strings(values, mask)  # type: ignore[arg-type]
    ours.validate(full=True)
    assert ours.equals(pa.array(list(values), pa.string(), mask=mask))


def test_text_that_is_not_utf8_or_not_text_is_refused() -> None:
    with pytest.raises(UnicodeDecodeError):
        arrow.strings([b"\xff"])
    with pytest.raises(TypeError, match="expected text"):
        arrow.strings([3])  # type: ignore[list-item]


@pytest.mark.parametrize("n", [0, 1, 5])
def test_repeat(n: int) -> None:
    ours = arrow.repeat("84128d061034aaa1", n)
    ours.validate(full=True)
    assert ours.equals(pa.array(["84128d061034aaa1"] * n, pa.string()))
    assert arrow.repeat("", n).to_pylist() == [""] * n


def test_no_pandas_is_imported() -> None:
    code = (
        "import sys, numpy as np, pyarrow as pa\n"
        "from codegen.apps.export import arrow, table\n"
        "arrow.array(np.arange(3.0), pa.float64(), np.array([False, True, False]))\n"
        "arrow.strings(['a', None]); arrow.repeat('x', 3); table.label('s', 3)\n"
        "print('pandas' in sys.modules)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    assert done.stdout.strip() == "False"

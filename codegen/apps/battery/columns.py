"""The concept columns a conversion fills: one :class:`ConceptColumn` per concept, numpy arrays.

Both conversions write these -- the columnar one (:mod:`.columnar`, whole columns at a time) and
the per-record one the tests check it with (tests/per_record.py, through the generated converters) -- so the two can be
compared exactly, and :mod:`.table` turns them into Arrow columns in one place.

Per kind: ``number`` float64, ``integer`` int64, ``bool`` bool, ``text`` object (str),
``choice`` int16 codes into the concept's choices, ``flags`` int64 bit sets over the concept's
choices (bit i = choices[i]), ``list`` a float64 matrix (NaN: an unknown element) and a length
per row. ``valid`` is False where the concept is unknown.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...ir import Concept

NDArray = Any  # numpy arrays (numpy's own annotations would tie mypy to one numpy version)

_DTYPES = {
    "number": np.float64,
    "integer": np.int64,
    "bool": np.bool_,
    "text": object,
    "choice": np.int16,
    "flags": np.int64,
}


@dataclass
class ConceptColumn:
    """One concept over ``n`` records (see the module docstring)."""

    concept: Concept
    values: NDArray
    valid: NDArray
    lengths: NDArray | None = None  # list concepts: the number of elements of each row
    blank: bool = False  # never written: shared read-only arrays, unknown everywhere

    @classmethod
    def empty(cls, concept: Concept, n: int, width: int = 0) -> ConceptColumn:
        if concept.kind == "list":
            return cls(concept, np.full((n, width), np.nan), np.zeros(n, bool), np.zeros(n, np.int64))
        values = np.full(n, None, object) if concept.kind == "text" else np.zeros(n, _DTYPES[concept.kind])
        return cls(concept, values, np.zeros(n, bool))

    def _own(self) -> None:
        """Arrays of its own to write into (an unknown column's are shared and read-only)."""
        self.blank = False
        if not self.valid.flags.writeable:
            self.values, self.valid = self.values.copy(), self.valid.copy()
            self.lengths = None if self.lengths is None else self.lengths.copy()

    def set(self, values: NDArray, where: NDArray | None = None, *, take: bool = False) -> None:
        """Write ``values`` (an array or a scalar) where ``where`` holds (everywhere if None);
        ``take``: ``values`` is a new array nobody else holds, which the column may keep as it is."""
        if self.blank and isinstance(values, np.ndarray) and values.shape == self.valid.shape:
            # The first write of a whole column (the usual): the array itself if it is ours to take,
            # else a copy (``values`` may be a log's column, and later rules write into ours);
            # whatever it holds where it is unknown.
            self.values = values.astype(self.values.dtype, casting="unsafe", copy=not take)
            self.valid = np.ones(len(values), bool) if where is None else np.array(where, bool)
            self.blank = False
            return
        self._own()
        if where is None:
            self.values[...] = values
            self.valid[...] = True
            return
        np.copyto(self.values, values, where=where, casting="unsafe")
        self.valid |= where

    def assign(self, values: NDArray, valid: NDArray) -> None:
        """The whole column, what it held before forgotten (a lookup that finds nothing makes
        the concept unknown again)."""
        self.blank = False
        self.values = values.astype(self.values.dtype, casting="unsafe")
        self.valid = np.array(valid, bool)

    def set_list(self, values: NDArray, lengths: NDArray, where: NDArray) -> None:
        """Write the rows of a list concept where ``where`` holds (widening the matrix if needed)."""
        if self.blank or not self.valid.any():  # nothing written yet: take the rows as they are
            self.blank = False
            self.values = np.where(where[:, None], values, np.nan) if not where.all() else values
            self.lengths = np.where(where, lengths, 0)
            self.valid = where.copy()
            return
        self._own()
        width = max(self.values.shape[1], values.shape[1])
        if width > self.values.shape[1]:
            wider = np.full((self.values.shape[0], width), np.nan)
            wider[:, : self.values.shape[1]] = self.values
            self.values = wider
        self.values[where, : values.shape[1]] = values[where]
        self.values[where, values.shape[1] :] = np.nan
        assert self.lengths is not None
        self.lengths[where] = lengths[where]
        self.valid |= where


def floats(values: Sequence[float | None] | NDArray) -> NDArray:
    """Numbers as a float64 array, NaN where unknown (None in a sequence)."""
    if isinstance(values, np.ndarray):
        return np.asarray(values, np.float64)
    return np.array([np.nan if v is None else v for v in values], np.float64)


def length_key(field: str) -> str:
    """The column holding each row's length of a variable-length array field (DroneCAN ``[<=N]``),
    whose matrix is padded to its capacity."""
    return f"{field}#length"


def empty_columns(concepts: tuple[Concept, ...], n: int) -> dict[str, ConceptColumn]:
    """Every concept unknown for ``n`` records."""
    return {c.name: ConceptColumn.empty(c, n) for c in concepts}


class LazyColumns(dict[str, ConceptColumn]):
    """Every concept unknown for ``n`` records, its arrays made when a conversion first writes it;
    :meth:`done` gives the ones never written shared read-only arrays. A source maps some 20 of
    the ~50 concepts: allocating and zeroing the others for every chunk cost ~10 % of an export."""

    def __init__(self, concepts: tuple[Concept, ...], n: int) -> None:
        super().__init__()
        self.by_name = {c.name: c for c in concepts}
        self.n = n

    def __missing__(self, name: str) -> ConceptColumn:
        column = self[name] = _blank(self.by_name[name], self.n)
        return column

    def done(self) -> dict[str, ConceptColumn]:
        """Every concept, those never written unknown (read-only arrays, no memory of their own)."""
        for name, concept in self.by_name.items():
            if name not in self:
                dict.__setitem__(self, name, _blank(concept, self.n))
        return {name: self[name] for name in self.by_name}


def _blank(concept: Concept, n: int) -> ConceptColumn:
    """A concept unknown for ``n`` records, in shared read-only arrays: a text concept's values are
    None, the others' zero; its first whole-column write replaces them, any other write copies them."""
    values = _unknown(concept.kind, n)
    lengths = _unknown("lengths", n) if concept.kind == "list" else None
    return ConceptColumn(concept, values, _unknown("valid", n), lengths, blank=True)


@functools.lru_cache(maxsize=64)
def _unknown(kind: str, n: int) -> NDArray:
    """The read-only array of ``n`` unknown values of a kind (or ``valid`` flags, list ``lengths``),
    one for all the concepts, chunks and logs that use it (a small log's fixed cost otherwise)."""
    if kind == "text":
        return np.broadcast_to(np.full(1, None, object), (n,))
    dtype = {"valid": np.bool_, "lengths": np.int64}.get(kind) or _DTYPES.get(kind, np.float64)
    return np.broadcast_to(np.zeros(1, dtype), (n, 0) if kind == "list" else (n,))

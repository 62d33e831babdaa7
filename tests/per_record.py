"""The per-record conversion: each decoded record through the generated converter to the concepts
(``generated/convert``), gathered into the same :class:`ConceptColumn`\\ s the columnar path fills.

The reference the columnar conversion is checked against (tests/apps/test_export_columnar.py); the
export itself uses the columnar one, so this lives beside the tests.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, cast

import numpy as np

from codegen.apps.battery.catalog import Catalog, SourceMapping
from codegen.apps.battery.columns import ConceptColumn, empty_columns
from codegen.apps.conversion.convert import converters
from codegen.inputs.model import PlainData


def concept_converter(package: str, source: SourceMapping) -> Callable[[object], PlainData]:
    """The generated ``<endpoint> -> concepts`` converter of a package, strict policy."""
    module = converters(package)
    func = module.CONVERTERS[(source.endpoint, "concepts")]

    def convert(instance: object) -> PlainData:
        return cast(PlainData, func(instance, policy="strict"))

    return convert


def states_to_columns(catalog: Catalog, states: Sequence[PlainData]) -> dict[str, ConceptColumn]:
    """Concept states (``BatteryState``) as concept columns."""
    n = len(states)
    out = empty_columns(catalog.concepts, n)
    plain = [cast(Any, s) for s in states]
    for name, col in out.items():
        kind = col.concept.kind
        values = [getattr(s, name) for s in plain]
        known = np.array([v is not None for v in values], dtype=bool)
        if kind == "list":
            width = max((len(v) for v in values if v is not None), default=0)
            matrix = np.full((n, width), np.nan)
            lengths = np.zeros(n, np.int64)
            for i, v in enumerate(values):
                if v is not None:
                    matrix[i, : len(v)] = v
                    lengths[i] = len(v)
            col.set_list(matrix, lengths, known)
        elif kind == "choice":
            choices = col.concept.choices
            col.set(np.array([choices.index(v) if v is not None else 0 for v in values], np.int16), known)
        elif kind == "flags":
            bit = {c: 1 << i for i, c in enumerate(col.concept.choices)}
            col.set(np.array([sum(bit[x] for x in v) if v is not None else 0 for v in values], np.int64), known)
        elif kind == "text":
            col.set(np.array(values, dtype=object), known)
        else:
            fill = [v if v is not None else 0 for v in values]
            col.set(np.array(fill, dtype=col.values.dtype) if n else col.values, known)
    return out

"""The crate's converter module (``src/convert.rs``) from :func:`.converters.rust_converters`: the
concepts' struct, the helpers and map functions, the public converters; the run-time support
(``support/convert_runtime.rs``) is copied beside it."""

from __future__ import annotations

import re

import jinja2

from ...ir import Concept, Schema
from .convert_concepts import state_lines
from .converters import RustConverter, rust_converters

# what the generated functions may call of support/convert_runtime.rs
_RUNTIME = ("Reports", "absf", "f16_round", "float_int_lost", "roundf", "same_chars", "utf8_replace")


def render_convert(env: jinja2.Environment, schema: Schema) -> tuple[str | None, list[RustConverter], list[str]]:
    """(the module's text, unformatted, or None without converters; the converters; those left out)."""
    converters, functions, left = rust_converters(schema)
    if not converters:
        return None, converters, left
    concepts: dict[str, Concept] = {c.name: c for s in schema.mappings for c in s.concepts}
    body = "\n".join(functions.values()) + "\n".join(line for c in converters for line in c.body())
    runtime = [name for name in _RUNTIME if re.search(rf"\b{name}\b", body)]
    # the choices' constants no function names are left out (rustc: never used)
    state = [x for x in state_lines(concepts) if not (m := re.match(r"const (\w+):", x)) or m[1] in body]
    text = env.get_template("convert.rs.j2").render(
        state=state,
        functions=functions,
        converters=converters,
        runtime=runtime,
        same=".same(" in body,
    )
    return text, converters, left

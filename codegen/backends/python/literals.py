"""Python source literals for schema-supplied values: everything a schema says reaches generated
code only through these functions, so no name, comment or value can break out of a literal."""

from __future__ import annotations

import math
import unicodedata


def py_literal(value: object) -> str:
    """Deterministic Python source for a scalar, tuple or list value."""
    if value is None or isinstance(value, bool):
        return repr(value)
    if isinstance(value, int):
        return repr(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "math.nan"
        if math.isinf(value):
            return "math.inf" if value > 0 else "-math.inf"
        return repr(value)
    if isinstance(value, str):
        return repr(value)
    if isinstance(value, bytes):
        return repr(value)
    if isinstance(value, tuple):
        inner = ", ".join(py_literal(v) for v in value)
        return f"({inner},)" if len(value) == 1 else f"({inner})"
    if isinstance(value, list):
        return "[" + ", ".join(py_literal(v) for v in value) + "]"
    raise TypeError(f"no literal for {type(value).__name__}")


def _clean(text: str) -> str:
    # Control and format characters (other than newline/tab) would be invisible or break a line.
    return "".join(
        ch if ch in "\n\t" or unicodedata.category(ch)[0] != "C" else f"\\x{ord(ch):02x}" if ord(ch) < 256 else " "
        for ch in text
    )


def docstring(text: str, indent: str) -> str:
    """A triple-quoted docstring holding ``text`` verbatim, safe whatever the text contains."""
    body = _clean(text.strip("\n")).replace("\\", "\\\\").replace('"""', '\\"\\"\\"')
    body = "\n".join(line.rstrip() for line in body.splitlines())
    if body.endswith('"'):
        body += " "
    if "\n" not in body:
        return f'{indent}"""{body}"""'
    lines = body.split("\n")
    out = [f'{indent}"""{lines[0]}']
    out.extend(f"{indent}{line}" if line else "" for line in lines[1:])
    out.append(f'{indent}"""')
    return "\n".join(out)

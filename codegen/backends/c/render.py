"""The files of the C library: a header per message, rendered from the IR through jinja2 templates."""

from __future__ import annotations

import math
import shutil
import subprocess
from pathlib import Path

import jinja2

from ...errors import BattgenError
from ...ir import ArrayType, CompositeType, Constant, Message, PrimitiveKind, PrimitiveType, Schema, SourceFormat
from .types import ident, member, type_name

_HERE = Path(__file__).parent
# clang-format's style, passed whole so no .clang-format found on disk changes the output
STYLE = "{BasedOnStyle: LLVM, ColumnLimit: 100, SortIncludes: false}"
_FORMATS = (SourceFormat.DRONECAN, SourceFormat.MAVLINK, SourceFormat.UORB)


def _comment(text: str) -> str:
    """Schema text inside a C comment: one line, no comment terminator."""
    return " ".join(text.replace("*/", "* /").split())


def _literal(c: Constant) -> str | None:
    v = c.value
    if isinstance(v, bool):
        return "1" if v else "0"
    if isinstance(v, int):
        return f"{v}" + ("u" if v >= 0 else "") if abs(v) < 2**31 else f"{v}" + ("ULL" if v >= 0 else "LL")
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else None
    return None


def _dependencies(msg: Message) -> list[str]:
    out: list[str] = []
    for f in msg.fields:
        t = f.type
        while isinstance(t, ArrayType):
            t = t.element
        if isinstance(t, CompositeType) and t.name not in out:
            out.append(t.name)
    return out


def header_path(qualified: str) -> str:
    return qualified.replace(".", "/") + ".h"


def _message_context(msg: Message) -> dict[str, object]:
    members = []
    for f in msg.fields:
        if f.is_padding:
            continue
        notes = []
        if f.unit_text:
            notes.append(f"[{f.unit_text}]")
        if f.invalid is not None:
            notes.append(f"invalid: {f.invalid.text}")
        if isinstance(f.type, PrimitiveType) and f.type.kind is not PrimitiveKind.BOOL:
            notes.append(f.type.name)
        if f.doc:
            notes.append(f.doc)
        members.append({"decls": member(f.type, ident(f.name)), "note": _comment(" ".join(notes))})
    name = type_name(msg.qualified_name)
    constants = [
        {"name": f"{name.upper()}_{ident(c.name).upper()}", "value": lit, "doc": _comment(c.doc)}
        for c in msg.constants
        if (lit := _literal(c)) is not None
    ]
    return {
        "name": name,
        "guard": name.upper() + "_H",
        "qualified": msg.qualified_name,
        "doc": _comment(msg.doc),
        "members": members,
        "constants": constants,
        "includes": [header_path(d) for d in _dependencies(msg)],
        "struct_size": msg.uorb.struct_size if msg.uorb is not None else None,
        "dronecan": msg.dronecan,
        "mavlink": msg.mavlink,
    }


def _environment() -> jinja2.Environment:
    return jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(_HERE / "templates")),
        undefined=jinja2.StrictUndefined,
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
        autoescape=False,
    )


def clang_format(text: str, name: str) -> str:
    exe = shutil.which("clang-format")
    if exe is None:
        raise BattgenError("clang-format: not found; expected Debian's clang-format on PATH to format the C")
    done = subprocess.run(
        [exe, f"--style={STYLE}", f"--assume-filename={name}"],
        input=text,
        capture_output=True,
        text=True,
        check=False,
        timeout=60,
    )
    if done.returncode != 0:
        raise BattgenError(f"clang-format: failed on {name}: {done.stderr.strip()}")
    return done.stdout


def render_library(schema: Schema) -> dict[str, str]:
    """Relative path -> formatted text of every file of the C library."""
    env = _environment()
    header = env.get_template("message.h.j2")
    files: dict[str, str] = {}
    for msg in schema.messages:
        if msg.format not in _FORMATS:
            continue
        rel = header_path(msg.qualified_name)
        files[rel] = clang_format(header.render(m=_message_context(msg)), rel)
    headers = sorted(files)
    files["battgen.h"] = clang_format(env.get_template("battgen.h.j2").render(headers=headers), "battgen.h")
    files["README.md"] = env.get_template("README.md.j2").render(headers=headers)
    return files

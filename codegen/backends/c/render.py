"""The files of the C library: a header per message, rendered from the IR through jinja2 templates."""

from __future__ import annotations

import math
import re
import shutil
import subprocess
from pathlib import Path

import jinja2

from ...errors import BattgenError
from ...ir import ArrayType, CompositeType, Constant, Message, PrimitiveKind, PrimitiveType, Schema, SourceFormat
from .checks import CheckUse, check_uses, checks_of, validator
from .codecs import mavlink_codec, uorb_codec
from .convert_concepts import state_lines
from .converters import c_converters
from .cyphal_codec import cyphal_codec
from .dronecan_codec import BitCodec, dronecan_codec
from .rules import rule_lines
from .types import ident, member, type_name

_HERE = Path(__file__).parent
# clang-format's style, passed whole so no .clang-format found on disk changes the output
STYLE = "{BasedOnStyle: LLVM, ColumnLimit: 100, SortIncludes: false}"
_FORMATS = (SourceFormat.DRONECAN, SourceFormat.MAVLINK, SourceFormat.UORB)
# support headers copied verbatim (through clang-format, as every other file)
_SUPPORT = ("battgen_wire.h", "battgen_mavlink.h", "battgen_convert.h")
_CYPHAL_SUPPORT = "battgen_cyphal.h"


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


def _uses_loop(lines: list[str]) -> bool:
    return any(line.startswith("for (i = 0;") or "[i]" in line for line in lines)


def _union_checks(msg: Message, uses: list[CheckUse]) -> list[str]:
    """A union's validator: the checks of the field it holds only (the others are not sent)."""
    lines: list[str] = []
    for k, f in enumerate(msg.fields):
        mine = [u for u in uses if u.path.split(".")[0].split("[")[0] == f.name]
        if mine:
            lines += [f"if (m->union_tag == {k}u) {{", *validator(mine), "}"]
    return lines


def _message_context(schema: Schema, msg: Message) -> dict[str, object]:
    members = _members(msg)
    name = type_name(msg.qualified_name)
    if msg.dronecan is not None and msg.dronecan.union:
        held = "the field held, by its place (BATTGEN_..._TAG_<FIELD>); the others are not sent"
        members.insert(0, {"decls": ["uint8_t union_tag;"], "note": held})
    constants = [
        {"name": f"{name.upper()}_{ident(c.name).upper()}", "value": lit, "doc": _comment(c.doc)}
        for c in msg.constants
        if (lit := _literal(c)) is not None
    ]
    if msg.dronecan is not None and msg.dronecan.union:
        constants += [
            {"name": f"{name.upper()}_TAG_{ident(f.name).upper()}", "value": f"{k}u", "doc": ""}
            for k, f in enumerate(msg.fields)
        ]
    mav = mavlink_codec(msg)
    uorb = uorb_codec(msg)
    uses = check_uses(schema, msg)
    cross, most, _ = rule_lines(schema, msg)
    checks = _union_checks(msg, uses) if msg.dronecan is not None and msg.dronecan.union else validator(uses)
    checks += cross
    return {
        "name": name,
        "mavlink_codec": mav,
        "uorb_codec": uorb,
        "dronecan_codec": dronecan_codec(schema, msg),
        "checks": checks_of(schema, msg),
        "validate": checks,
        "validate_loops": _uses_loop(checks),
        "mavlink_loops": mav is not None and _uses_loop(mav.encode),
        "uorb_loops": uorb is not None and _uses_loop(uorb.encode),
        "max_problems": sum((u.check.count or 1) + (1 if u.check.dynamic else 0) for u in uses) + most,
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


def _source_view(context: dict[str, object]) -> dict[str, object]:
    """What the format's source file renders of one message (its codecs under short names)."""
    dc = context["dronecan_codec"]
    uses: dict[str, bool] = {}
    if isinstance(dc, BitCodec):
        for side, lines in (("put", dc.put), ("get", dc.get)):
            uses[f"{side}_e"] = any(line.startswith("e = ") for line in lines)
            uses[f"{side}_k"] = any(line.startswith("k = ") for line in lines)
            uses[f"{side}_u"] = any("&u)" in line for line in lines)
            uses[f"{side}_tao"] = any(re.search(r"\btao\b", line) for line in lines)
            uses[f"{side}_m"] = any("m->" in line for line in lines)
    return {
        **context,
        "dc": uses,
        "mavlink": context["mavlink_codec"],
        "uorb": context["uorb_codec"],
        "dronecan": context["dronecan_codec"],
    }


def _members(msg: Message) -> list[dict[str, object]]:
    """The struct members of a message (padding left out), each with its comment."""
    members: list[dict[str, object]] = []
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
    return members


def _cyphal_context(schema: Schema, msg: Message) -> dict[str, object]:
    """What the Cyphal header and source render of one type: its struct, constants and codec (the
    variables each function declares found in its statements)."""
    codec = cyphal_codec(schema, msg)
    assert codec is not None, msg.qualified_name
    name = type_name(msg.qualified_name)
    members = _members(msg)
    constants = [
        {"name": f"{name.upper()}_{ident(c.name).upper()}", "value": lit, "doc": _comment(c.doc)}
        for c in msg.constants
        if (lit := _literal(c)) is not None
    ]
    if msg.is_union:
        held = "the field held, by its place (BATTGEN_..._TAG_<FIELD>); the others are not sent"
        members.insert(0, {"decls": ["uint8_t union_tag;"], "note": held})
        constants += [
            {"name": f"{name.upper()}_TAG_{ident(f.name).upper()}", "value": f"{k}u", "doc": ""}
            for k, f in enumerate(msg.fields)
        ]

    def uses(lines: list[str]) -> dict[str, bool]:
        text = "\n".join(lines)
        return {
            "e": any(line.startswith("e = ") for line in lines),
            "i": "[i]" in text or "(i = 0;" in text,
            "h": any(line.startswith("h = ") for line in lines),
            "u": any(line.startswith("u = ") for line in lines),
            "sub": "&sub" in text,
            "m": "m->" in text,
        }

    return {
        "name": name,
        "qualified": msg.qualified_name,
        "guard": name.upper() + "_H",
        "doc": _comment(msg.doc),
        "members": members,
        "constants": constants,
        "includes": [header_path(d) for d in _dependencies(msg)],
        "codec": codec,
        "put_uses": uses(codec.put),
        "get_uses": uses(codec.get),
    }


def _cyphal_files(schema: Schema, env: jinja2.Environment) -> dict[str, str]:
    """The Cyphal types' headers, ``cyphal.c`` and ``battgen_cyphal.h`` (nothing without Cyphal types)."""
    contexts = [_cyphal_context(schema, m) for m in schema.messages if m.format is SourceFormat.CYPHAL]
    if not contexts:
        return {}
    header = env.get_template("cyphal.h.j2")
    files = {}
    for c in contexts:
        rel = header_path(str(c["qualified"]))
        files[rel] = clang_format(header.render(m=c), rel)
    source = env.get_template("cyphal.c.j2").render(headers=sorted(files), messages=contexts)
    files["cyphal.c"] = clang_format(source, "cyphal.c")
    text = (_HERE / "support" / _CYPHAL_SUPPORT).read_text(encoding="utf-8")
    files[_CYPHAL_SUPPORT] = clang_format(text, _CYPHAL_SUPPORT)
    return files


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
    source = env.get_template("format.c.j2")
    files: dict[str, str] = {}
    contexts: dict[SourceFormat, list[dict[str, object]]] = {}
    for msg in schema.messages:
        if msg.format not in _FORMATS:
            continue
        rel = header_path(msg.qualified_name)
        context = _message_context(schema, msg)
        contexts.setdefault(msg.format, []).append(context)
        files[rel] = clang_format(header.render(m=context), rel)
    cyphal = _cyphal_files(schema, env)
    headers = sorted([*files, *(rel for rel in cyphal if rel.endswith(".h") and "/" in rel)])
    files.update(cyphal)
    for fmt, messages in sorted(contexts.items(), key=lambda item: item[0].value):
        rel = f"{fmt.value}.c"
        own = sorted(header_path(str(m["qualified"])) for m in messages)
        view = [_source_view(m) for m in messages]
        files[rel] = clang_format(source.render(format=fmt.value, headers=own, messages=view), rel)
    for name in _SUPPORT:
        files[name] = clang_format((_HERE / "support" / name).read_text(encoding="utf-8"), name)
    converters, helpers, left = c_converters(schema)
    if converters:
        used = sorted(
            {header_path(q) for c in converters for q in (*(s[0] for s in c.sources), *(t[0] for t in c.targets))}
        )
        text = env.get_template("convert.h.j2").render(headers=used, converters=converters)
        files["convert.h"] = clang_format(text, "convert.h")
        state = state_lines({c.name: c for s in schema.mappings for c in s.concepts})
        text = env.get_template("convert.c.j2").render(state=state, functions=helpers, converters=converters)
        files["convert.c"] = clang_format(text, "convert.c")
        headers.append("convert.h")
    files["battgen.h"] = clang_format(env.get_template("battgen.h.j2").render(headers=headers), "battgen.h")
    files["README.md"] = env.get_template("README.md.j2").render(headers=headers, converters=converters, left=left)
    return files

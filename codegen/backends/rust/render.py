"""The files of the Rust crate, rendered from the IR through jinja2 templates (one per IR concept:
message, enum, namespace module) and formatted by rustfmt; the support modules under ``support/``
are copied verbatim and formatted the same way."""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from collections import defaultdict
from pathlib import Path

import jinja2

from ...errors import BattgenError
from ...ir import CompositeType, Message, Schema, SourceFormat
from .convert_module import render_convert
from .cyphal_codec import cyphal_modules
from .model import MessageView, message_view, shared_enums
from .params import render_params
from .types import element

_HERE = Path(__file__).parent
_FORMATS = (SourceFormat.DRONECAN, SourceFormat.MAVLINK, SourceFormat.UORB)
# the crate's own version (its API, not battgen's release): raised when the generated API changes
CRATE_VERSION = "0.1.0"
SUPPORT = ("crc", "dronecan_wire", "failsafe", "mavlink_wire", "problems", "rules", "same", "uorb_wire", "wire")
# the Cyphal codecs' bits (cyphal_codec), beside the rest (rustfmt sorts the `mod` lines)
CRATE_SUPPORT = (*SUPPORT, "cyphal_wire")


def _environment() -> jinja2.Environment:
    return jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(_HERE / "templates")),
        undefined=jinja2.StrictUndefined,
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
        autoescape=False,
    )


def rustfmt(files: dict[str, str], config: str) -> dict[str, str]:
    """The ``.rs`` files formatted by rustfmt with ``config`` (the crate's rustfmt.toml), in one run."""
    exe = shutil.which("rustfmt")
    if exe is None:
        raise BattgenError("rustfmt: not found; expected rustup's rustfmt on PATH to format the Rust crate")
    with tempfile.TemporaryDirectory(prefix="battgen-rustfmt-") as tmp:
        root = Path(tmp)
        (root / "rustfmt.toml").write_text(config, encoding="utf-8")
        paths = []
        for rel, text in files.items():
            path = root / "crate" / rel
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text, encoding="utf-8")
            paths.append(str(path))
        # files given one by one: rustfmt formats each without following `mod` declarations
        done = subprocess.run(
            [exe, "--config-path", str(root / "rustfmt.toml"), "--edition", "2021", *paths],
            capture_output=True,
            text=True,
            check=False,
            timeout=120,
        )
        if done.returncode != 0:
            raise BattgenError(f"rustfmt: failed: {done.stderr.strip()[:2000]}")
        return {rel: (root / "crate" / rel).read_text(encoding="utf-8") for rel in files}


ModulePath = tuple[str, ...]  # a module path under the crate root


def _modules(views: list[MessageView]) -> tuple[dict[ModulePath, set[str]], dict[ModulePath, list[tuple[str, str]]]]:
    """Namespace modules -> their submodules, and -> the (module, struct) pairs they re-export."""
    children: dict[ModulePath, set[str]] = defaultdict(set)
    exports: dict[ModulePath, list[tuple[str, str]]] = defaultdict(list)
    for v in views:
        parts = tuple(v.module)
        for i in range(len(parts)):
            children[parts[:i]].add(parts[i])
        exports[parts[:-1]].append((parts[-1], v.name))
    return children, exports


def rust_messages(schema: Schema) -> list[Message]:
    """The messages of the crate: DroneCAN, MAVLink and uORB ones (a DSDL union as a struct of its
    fields and the `union_tag` saying which one is held, as the C library holds it)."""
    held: dict[str, Message] = {m.qualified_name: m for m in schema.messages if m.format in _FORMATS}
    out: dict[str, bool] = {}

    def ok(m: Message) -> bool:
        if m.qualified_name not in out:
            out[m.qualified_name] = False  # a cycle is no valid schema; refuse it rather than recurse
            nested = [element(f.type) for f in m.fields]
            out[m.qualified_name] = all(
                not isinstance(t, CompositeType) or (t.name in held and ok(held[t.name])) for t in nested
            )
        return out[m.qualified_name]

    return [m for m in held.values() if ok(m)]


def render_crate(schema: Schema) -> dict[str, str]:
    """Relative path -> text of every file of the crate (the Rust formatted by rustfmt)."""
    env = _environment()
    formats = tuple(f.value for f in _FORMATS)
    shared = shared_enums(schema, formats)
    views = [message_view(schema, m, shared) for m in rust_messages(schema)]
    rs: dict[str, str] = {}
    message = env.get_template("message.rs.j2")
    for v in views:
        rs["src/" + "/".join(v.module) + ".rs"] = message.render(m=v)
    children, exports = _modules(views)
    by_format: dict[str, list[object]] = defaultdict(list)
    for e in shared.values():
        by_format[e.qualified.split(".")[0]].append(e)
    for fmt, enums in sorted(by_format.items()):
        rs[f"src/{fmt}/enums.rs"] = env.get_template("enums.rs.j2").render(format=fmt, enums=enums)
        children[(fmt,)].add("enums")
    module = env.get_template("mod.rs.j2")
    for parts, subs in sorted(children.items()):
        if not parts:
            continue
        what = "the messages of this namespace" if len(parts) > 1 else f"the {parts[0]} messages"
        rs["src/" + "/".join(parts) + "/mod.rs"] = module.render(
            path="::".join(parts),
            name=parts[-1],
            what=what,
            modules=sorted(subs),
            reexports=sorted(exports.get(parts, [])),
        )
    cyphal = cyphal_modules(schema, env)
    if cyphal:
        rs.update(cyphal)
        children[()].add("cyphal")
    for name in CRATE_SUPPORT:
        text = (_HERE / "support" / f"{name}.rs").read_text(encoding="utf-8")
        head = f"// Copied by battgen from codegen/backends/rust/support/{name}.rs; do not edit.\n"
        rs[f"src/{name}.rs"] = head + text
    qualified = sorted(v.qualified for v in views)
    # the README's example decodes a MAVLink BATTERY_STATUS: shown (and run as a doc test) when it is there
    example = "mavlink.BATTERY_STATUS" in qualified
    params = render_params(schema)
    if params is not None:
        rs["src/params.rs"] = params
        children[()].add("params")
    convert, _, _ = render_convert(env, schema)
    if convert is not None:  # the converters, and their run-time support copied beside them
        rs["src/convert.rs"] = convert
        text = (_HERE / "support" / "convert_runtime.rs").read_text(encoding="utf-8")
        rs["src/convert_runtime.rs"] = (
            "// Copied by battgen from codegen/backends/rust/support/convert_runtime.rs; do not edit.\n" + text
        )
        children[()] |= {"convert", "convert_runtime"}
    rs["src/lib.rs"] = env.get_template("lib.rs.j2").render(
        support=CRATE_SUPPORT, modules=sorted(children[()]), example=example
    )
    config = env.get_template("rustfmt.toml.j2").render()
    files = rustfmt(rs, config)
    files["Cargo.toml"] = env.get_template("Cargo.toml.j2").render(version=CRATE_VERSION)
    files["rustfmt.toml"] = config
    files["README.md"] = env.get_template("README.md.j2").render(messages=qualified, example=example)
    files[".gitignore"] = "# cargo's build output, never committed\n/target/\nCargo.lock\n"
    return dict(sorted(files.items()))

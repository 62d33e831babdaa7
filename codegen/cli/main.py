"""The ``battgen`` command line. Exit codes: 0 ok, 1 check failed or invalid, 2 bad usage or
malformed schema. Errors are one line on stderr, never a traceback."""

from __future__ import annotations

import argparse
import importlib
import shutil
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from .. import __version__
from ..errors import BattgenError, ErrorList
from ..text.escape import line

if TYPE_CHECKING:
    from ..ir import Schema

EXIT_OK, EXIT_FAILED, EXIT_USAGE = 0, 1, 2
# The commands kept in their own modules (codegen/cli/<name>.py), in the order of the help text, with the
# one-line summary `battgen --help` lists. Only the module of the command a run names is imported (it adds its
# arguments with register(subparsers, summary)): a command's dependencies (the code generator, numpy, pandas,
# python-can, ...) are paid by that command alone, and `battgen --help` imports none of them.
COMMANDS: tuple[tuple[str, str], ...] = (
    ("validate", "check data files, parameter files and flight/telemetry logs (.ulg, .tlog, .mav) against a message"),
    ("docs", "write a Markdown reference page per message (PX4 message reference layout)"),
    ("schema", "print or write the JSON Schema (Draft 2020-12) of messages"),
    ("convert", "convert battery records between formats (JSON, JSON Lines, YAML, binary)"),
    ("vectors", "JSON conformance vectors of a converter (input -> expected output and loss report)"),
    ("params", "propose battery failsafe parameters from a devicetree battery, or check a parameter file"),
    ("failsafe", "replay a flight log (.ulg, .tlog, .bin) or JSON Lines samples through PX4's or ArduPilot's failsafe"),
    ("can", "account for a DroneCAN capture or live bus: nodes, rates, transport errors"),
    ("export", "export the battery records of many logs into a Parquet dataset (needs battgen[fleet])"),
    ("query", "run SQL over an exported dataset with DuckDB (table battery, views flights and packs)"),
    ("report", "an HTML report (or PNG images) of a flight's battery: plots, failsafe replay, findings, figures"),
)


def _load(paths: Sequence[str], args: argparse.Namespace) -> Schema:
    from ..apps.schemas.package import bundled_schemas, load_schemas

    include_paths = [Path(p) for p in args.include_path or ()]
    if paths or include_paths:
        from ..frontends.loader import load

        schema = load([Path(p) for p in paths] if paths else [bundled_schemas()], include_paths=include_paths)
    else:  # the bundled schemas, from the IR cache
        schema = load_schemas(bundled_schemas())
    for warning in schema.warnings:  # accepted, as upstream's tools accept it, but worth a look
        print(line(f"battgen: {warning}"), file=sys.stderr)
    return schema


def _include_path_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--include-path",
        action="append",
        metavar="DIR",
        help="a folder MAVLink <include>s may read from besides the schema folder (repeatable)",
    )


def cmd_list(args: argparse.Namespace) -> int:
    schema = _load(args.paths, args)
    for msg in schema.messages:
        print(line(msg.qualified_name))
    return EXIT_OK


def cmd_ir(args: argparse.Namespace) -> int:
    from ..ir import json_form as irjson

    schema = _load(args.paths, args)
    sys.stdout.write(irjson.dumps(schema))
    return EXIT_OK


def _generate_c(schema: Schema, out: Path, check: bool) -> int:
    from ..backends.c import generate_c

    return _report_library(out, check, *generate_c(schema, out, check=check))


def _generate_rust(schema: Schema, out: Path, check: bool) -> int:
    from ..backends.rust import generate_rust

    return _report_library(out, check, *generate_rust(schema, out, check=check))


def _report_library(out: Path, check: bool, written: list[str], removed: list[str], unchanged: list[str]) -> int:
    if check and (written or removed):
        for rel in written:
            print(line(f"stale: {out / rel}"), file=sys.stderr)
        for rel in removed:
            print(line(f"not generated any more: {out / rel}"), file=sys.stderr)
        print(line(f"{out} is stale: run 'battgen generate'"), file=sys.stderr)
        return EXIT_FAILED
    print(line(f"{out}: {len(written)} written, {len(removed)} removed, {len(unchanged)} unchanged"))
    return EXIT_OK


def cmd_generate(args: argparse.Namespace) -> int:
    # the code generator is imported by this command only
    from ..apps.schemas.package import project_root
    from ..backends.python.name_clashes import refuse_clashes
    from ..backends.python.writer import generate

    started = time.perf_counter()
    schema = _load([args.schema_dir] if args.schema_dir else [], args)
    refuse_clashes(schema)  # before either language writes a file
    if args.lang == "c":
        return _generate_c(schema, Path(args.out) if args.out else project_root() / "generated" / "c", args.check)
    if args.lang == "rust":
        return _generate_rust(schema, Path(args.out) if args.out else project_root() / "generated" / "rust", args.check)
    if args.lang is None and not args.out:
        # the C is formatted by clang-format: a machine without it still generates (and checks) the Python
        # package, the main job; CI installs clang-format, and tests/backends/test_c_headers.py checks generated/c
        if shutil.which("clang-format") is None:
            print(
                "battgen: generated/c left as it is: clang-format is not installed (Debian: clang-format)",
                file=sys.stderr,
            )
        else:
            status = _generate_c(schema, project_root() / "generated" / "c", args.check)
            if status != EXIT_OK:
                return status
        # the same for the Rust crate and rustfmt (tests/backends/test_rust_crate.py checks generated/rust)
        if shutil.which("rustfmt") is None:
            print("battgen: generated/rust left as it is: rustfmt is not installed (rustup's rustfmt)", file=sys.stderr)
        else:
            status = _generate_rust(schema, project_root() / "generated" / "rust", args.check)
            if status != EXIT_OK:
                return status
    out = Path(args.out) if args.out else project_root() / "generated"
    if not out.name.isidentifier():
        raise BattgenError(
            f"{out}: the output folder's name is the package's import name, so it must be a Python identifier"
        )
    if out.exists() and not out.is_dir():
        raise BattgenError(f"--out {out}: is a file; expected a folder for the package")
    try:
        result = generate(schema, out, check=args.check)
    except OSError as exc:
        raise BattgenError(f"--out {out}: cannot write: {exc.strerror or exc}") from None
    elapsed = time.perf_counter() - started
    if args.check:
        if result.stale:
            for rel in result.written:
                print(line(f"stale: {out / rel}"), file=sys.stderr)
            for rel in result.removed:
                print(line(f"not generated any more: {out / rel}"), file=sys.stderr)
            print(line(f"{out} is stale: run 'battgen generate'"), file=sys.stderr)
            return EXIT_FAILED
        print(line(f"{out} is up to date ({len(result.unchanged)} files, {len(schema.messages)} messages)"))
        return EXIT_OK
    for rel in result.written:
        print(line(f"wrote {out / rel}"))
    for rel in result.removed:
        print(line(f"removed {out / rel}"))
    print(
        line(
            f"generated {len(schema.messages)} messages into {out}: {len(result.written)} written, "
            f"{len(result.unchanged)} unchanged, {len(result.removed)} removed in {elapsed * 1000:.0f} ms"
        )
    )
    return EXIT_OK


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # type: ignore[override]
        self.print_usage(sys.stderr)
        print(line(f"{self.prog}: error: {message}"), file=sys.stderr)
        raise SystemExit(EXIT_USAGE)


def _command_named(argv: Sequence[str]) -> str | None:
    """The command a command line names: the first word that is not an option (battgen's own options take no
    value), or None."""
    return next((arg for arg in argv if not arg.startswith("-")), None)


def build_parser(argv: Sequence[str] | None = None) -> argparse.ArgumentParser:
    """The parser of every command; given the command line, only the command it names is complete (its module
    imported), the others are listed by name and summary, which is all that parsing that line can show."""
    wanted = None if argv is None else _command_named(argv)
    parser = _Parser(prog="battgen", description="Battery telemetry schemas: one IR, generated models.")
    parser.add_argument("--version", action="version", version=f"battgen {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    p = sub.add_parser("list", help="print the qualified names of the messages in a schema folder or files")
    p.add_argument("paths", nargs="*", help="schema folders or files (default: the bundled schemas/)")
    _include_path_option(p)
    p.set_defaults(func=cmd_list)

    p = sub.add_parser("ir", help="print the IR as JSON")
    p.add_argument("paths", nargs="*", help="schema folders (uorb/, dronecan/, devicetree/, mavlink/) or single files")
    _include_path_option(p)
    p.set_defaults(func=cmd_ir)

    p = sub.add_parser("generate", help="generate the Python package (default: schemas/ into generated/)")
    p.add_argument("schema_dir", nargs="?", help="schema folder (default: schemas/)")
    p.add_argument(
        "--out",
        "-o",
        help="write here (Python: an importable package named as the folder; C: default generated/c; "
        "Rust: default generated/rust)",
    )
    p.add_argument(
        "--lang",
        choices=("python", "c", "rust"),
        help="only this language (default: all, C into generated/c, the Rust crate into generated/rust)",
    )
    p.add_argument("--check", action="store_true", help="write nothing; exit 1 naming stale files")
    _include_path_option(p)
    p.set_defaults(func=cmd_generate)

    for name, summary in COMMANDS:
        if argv is None or name == wanted:
            importlib.import_module(f"{__package__}.{name}").register(sub, summary)
        else:
            sub.add_parser(name, help=summary)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    if argv is None:
        argv = sys.argv[1:]
    parser = build_parser(argv)
    args = parser.parse_args(argv)
    func: Callable[[argparse.Namespace], int] = args.func
    try:
        return func(args)
    except ErrorList as exc:  # every problem of the run, one line each, then the count
        for error in exc.errors:
            print(line(f"battgen: {error}"), file=sys.stderr)
        print(line(f"battgen: {len(exc.errors)} errors"), file=sys.stderr)
        return EXIT_USAGE
    except BattgenError as exc:
        print(line(f"battgen: {exc}"), file=sys.stderr)
        return EXIT_USAGE
    except ModuleNotFoundError as exc:  # a dependency missing from this environment, e.g. pymavlink
        print(
            f"battgen: needs the Python package {exc.name!r}: install battgen with pip (pip install -e .)",
            file=sys.stderr,
        )
        return EXIT_USAGE
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:
        return EXIT_OK


if __name__ == "__main__":
    raise SystemExit(main())

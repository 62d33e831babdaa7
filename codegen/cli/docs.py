"""``battgen docs [SCHEMA_DIR] [--out DIR] [--check]``: Markdown reference pages, one per message.

Pages are written to ``--out`` (default ``docs/messages`` in the current folder); pages this
command wrote earlier for messages that no longer exist are removed. ``--check`` writes nothing
and exits 1 naming the pages that are stale.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from ..apps.package import bundled_schemas
from ..backends.markdown import MARKER, render_docs
from ..errors import BattgenError
from ..frontends.loader import load

EXIT_OK, EXIT_STALE = 0, 1


def _ours(path: Path) -> bool:
    """Whether a Markdown file was written by this command (only those are ever removed)."""
    try:
        with path.open(encoding="utf-8") as stream:
            return stream.readline().rstrip("\n") == MARKER
    except (OSError, UnicodeDecodeError):
        return False


def write_docs(pages: dict[str, str], out: Path, *, check: bool) -> tuple[list[str], list[str], list[str]]:
    """(written, removed, unchanged) page names; with ``check`` nothing is written or removed."""
    written, unchanged = [], []
    for name, text in pages.items():
        target = out / name
        data = text.encode("utf-8")
        try:
            same = target.is_file() and target.read_bytes() == data
        except OSError:
            same = False
        if same:
            unchanged.append(name)
            continue
        written.append(name)
        if not check:
            try:
                out.mkdir(parents=True, exist_ok=True)
                target.write_bytes(data)
            except OSError as exc:
                raise BattgenError(f"{target}: cannot write: {exc.strerror or exc}") from None
    removed = sorted(p.name for p in out.glob("*.md") if p.name not in pages and _ours(p)) if out.is_dir() else []
    if not check:
        for name in removed:
            (out / name).unlink()
    return written, removed, unchanged


def run(args: argparse.Namespace) -> int:
    schema = load([Path(args.schema_dir)] if args.schema_dir else [bundled_schemas()])
    out = Path(args.out) if args.out else Path("docs") / "messages"
    pages = render_docs(schema)
    written, removed, unchanged = write_docs(pages, out, check=args.check)
    if args.check:
        if written or removed:
            for name in written:
                print(f"stale: {out / name}", file=sys.stderr)
            for name in removed:
                print(f"not generated any more: {out / name}", file=sys.stderr)
            print(f"{out} is stale: run 'battgen docs'", file=sys.stderr)
            return EXIT_STALE
        print(f"{out} is up to date ({len(unchanged)} pages)")
        return EXIT_OK
    for name in written:
        print(f"wrote {out / name}")
    for name in removed:
        print(f"removed {out / name}")
    print(f"{len(pages)} pages in {out}: {len(written)} written, {len(unchanged)} unchanged, {len(removed)} removed")
    return EXIT_OK


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "docs",
        help="write a Markdown reference page per message (PX4 message reference layout)",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("schema_dir", nargs="?", help="schema folder (default: the bundled schemas/)")
    p.add_argument("--out", metavar="DIR", help="output folder (default: docs/messages)")
    p.add_argument("--check", action="store_true", help="write nothing; exit 1 naming stale pages")
    p.set_defaults(func=run)

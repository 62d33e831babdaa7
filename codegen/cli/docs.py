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

from ..apps.schemas.docs import write_docs
from ..apps.schemas.package import bundled_schemas
from ..backends.markdown import render_docs
from ..errors import BattgenError
from ..frontends.loader import load
from ..text.escape import line

EXIT_OK, EXIT_STALE = 0, 1


def run(args: argparse.Namespace) -> int:
    schema = load([Path(args.schema_dir)] if args.schema_dir else [bundled_schemas()])
    out = Path(args.out) if args.out else Path("docs") / "messages"
    if out.exists() and not out.is_dir():
        raise BattgenError(f"--out {out}: is a file; expected a folder for the pages")
    pages = render_docs(schema)
    written, removed, unchanged = write_docs(pages, out, check=args.check)
    if args.check:
        if written or removed:
            for name in written:
                print(line(f"stale: {out / name}"), file=sys.stderr)
            for name in removed:
                print(line(f"not generated any more: {out / name}"), file=sys.stderr)
            print(line(f"{out} is stale: run 'battgen docs'"), file=sys.stderr)
            return EXIT_STALE
        print(line(f"{out} is up to date ({len(unchanged)} pages)"))
        return EXIT_OK
    for name in written:
        print(line(f"wrote {out / name}"))
    for name in removed:
        print(line(f"removed {out / name}"))
    print(
        line(f"{len(pages)} pages in {out}: {len(written)} written, {len(unchanged)} unchanged, {len(removed)} removed")
    )
    return EXIT_OK


def register(subparsers: Any, summary: str) -> None:
    p = subparsers.add_parser(
        "docs",
        help=summary,
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("schema_dir", nargs="?", help="schema folder (default: the bundled schemas/)")
    p.add_argument("--out", metavar="DIR", help="output folder (default: docs/messages)")
    p.add_argument("--check", action="store_true", help="write nothing; exit 1 naming stale pages")
    p.set_defaults(func=run)

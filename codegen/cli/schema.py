"""``battgen schema``: the JSON Schema (Draft 2020-12) export of messages.

``--message NAME`` prints one message's schema; ``--out DIR`` writes ``<qualified name>.schema.json``
for every message; with neither, one JSON object maps each qualified name to its schema.
NaN and the infinities are the strings "NaN", "Infinity", "-Infinity" (see codegen.ir.numbers).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from ..apps.schemas.messages import resolve_message
from ..apps.schemas.package import bundled_schemas
from ..backends.json_schema import export_all, message_json_schema
from ..errors import BattgenError
from ..frontends.loader import load
from ..text.escape import line


def _dumps(doc: Any) -> str:
    return json.dumps(doc, indent=2, allow_nan=False) + "\n"


def run(args: argparse.Namespace) -> int:
    schema = load([Path(args.schemas)] if args.schemas else [bundled_schemas()])
    if args.message:
        sys.stdout.write(_dumps(message_json_schema(schema, resolve_message(schema, args.message))))
        return 0
    documents = export_all(schema)
    if args.out is None:
        sys.stdout.write(_dumps(documents))
        return 0
    out = Path(args.out)
    try:
        out.mkdir(parents=True, exist_ok=True)
        for name, doc in documents.items():
            (out / f"{name}.schema.json").write_text(_dumps(doc), encoding="utf-8")
    except OSError as exc:
        raise BattgenError(f"{out}: cannot write: {exc.strerror or exc}") from None
    print(line(f"wrote {len(documents)} JSON Schemas into {out}"))
    return 0


def register(subparsers: Any, summary: str) -> None:
    p = subparsers.add_parser(
        "schema",
        help=summary,
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--schemas", metavar="DIR", help="schema folder (default: the bundled schemas/)")
    group = p.add_mutually_exclusive_group()
    group.add_argument("--message", metavar="NAME", help="one message (qualified or unambiguous short name)")
    group.add_argument("--out", metavar="DIR", help="write <qualified name>.schema.json per message here")
    p.set_defaults(func=run)

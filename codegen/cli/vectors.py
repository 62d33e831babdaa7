"""``battgen vectors --from A --to B [--policy P] [-o FILE]``: conformance vectors of one converter.

Writes one JSON document: for the source side's baseline record and for every edge of every field
(its "unknown" sentinel, NaN, range and type limits, each enum entry or bitmask bit, arrays empty,
partly and fully filled), the input record, the output our generated converter gives under the
policy and its loss report (or the error it gives). Other projects replay them against their own
converters; ``coverage`` lists the edges written per field. Exit 0, 2 for an unknown pair or policy.
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from ..apps.conversion.vectors import vectors_document
from ..text.escape import line
from .convert import open_output


def register(subparsers: Any, summary: str) -> None:
    p = subparsers.add_parser(
        "vectors",
        help=summary,
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--from", dest="source", required=True, help="source side (dronecan, uorb, uorb_v0, mavlink)")
    p.add_argument("--to", dest="target", required=True, help="target side (any, 'concepts' included)")
    p.add_argument(
        "--policy",
        choices=("strict", "px4", "ardupilot"),
        default="strict",
        help="strict (default), px4 or ardupilot: as the specifications say, or as that firmware's code does",
    )
    p.add_argument("-o", "--output", help="output file (default: standard output)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    doc = vectors_document(args.source, args.target, args.policy)
    text = json.dumps(doc, indent=1, allow_nan=False) + "\n"
    if args.output:
        with open_output(args.output) as out:
            out.write(text.encode("utf-8"))
        vectors = doc["vectors"]
        count = len(vectors) if isinstance(vectors, list) else 0
        print(
            line(f"wrote {count} vectors of {doc['source']} -> {doc['target']} ({doc['policy']}) to {args.output}"),
            file=sys.stderr,
        )
    else:
        sys.stdout.write(text)
    return 0

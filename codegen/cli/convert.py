"""``battgen convert``: move battery records between formats with the generated converters.

Records come as JSON (an object or an array of them), JSON Lines (streamed, one record a line),
YAML (a mapping or a list; several documents allowed), or binary payloads (``hex``: one record a
line, the payloads of a multi-message side separated by spaces; ``raw``: one payload a file)
decoded and encoded by the generated codecs. A record of a side with several messages
(DroneCAN: BatteryInfo plus BatteryInfoAux) is keyed by alias (``{"info": {...}, "aux": {...}}``);
a bare object is the first message. Errors name the input and record line; exit code 2.

Logs convert every record they hold: PX4 flight logs (``ulog``, .ulg: every record of the source
uORB message's topics, all multi_ids, in file order; a log format that differs from the schema is
one warning on stderr, and fields the log lacks keep their defaults), MAVLink telemetry logs
(``tlog``, .tlog) and raw MAVLink streams (``mavlink``, .mav): every frame of the source message,
with bad CRCs and garbage skipped and summed up in one warning. ``--from``/``--to`` take a side
name or a message name (``uorb.BatteryStatus``, ``mavlink.BATTERY_STATUS``).
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Iterable
from pathlib import Path
from typing import IO, Any, Literal

import yaml

from ..apps.convert import FORMATS, LOG_FORMATS, Conversion, Converted, input_format, output_format
from ..errors import BattgenError
from ..inputs.records import Notice


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "convert", help="convert battery records between formats (JSON, JSON Lines, YAML, binary)"
    )
    p.add_argument("--from", dest="source", required=True, help="source side (dronecan, uorb, uorb_v0, mavlink, ...)")
    p.add_argument("--to", dest="target", required=True, help="target side, or 'concepts' for the shared state")
    p.add_argument("--policy", choices=("strict", "px4"), default="strict", help="strict (default) or px4")
    p.add_argument("--report", action="store_true", help="add each record's loss report (to stderr for binary output)")
    p.add_argument(
        "--report-summary",
        action="store_true",
        help="as --report, but the loss as a short text: one line per kind, fields grouped by message",
    )
    p.add_argument("files", nargs="*", help="input files (default: standard input)")
    p.add_argument("-o", "--output", help="output file (default: standard output)")
    p.add_argument(
        "--in-format",
        "--input-format",
        choices=FORMATS + LOG_FORMATS,
        help="input format (default: from the extension, else jsonl; .ulg ulog, .tlog tlog, .mav mavlink)",
    )
    p.add_argument("--out-format", choices=FORMATS, help="output format (default: the input's, text for binary)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help="extra converter input (number)")
    p.add_argument("--package", default="generated", help="the generated package to use (default: generated)")
    p.set_defaults(func=run)


def _inputs(settings: list[str]) -> dict[str, float]:
    out = {}
    for item in settings:
        name, eq, value = item.partition("=")
        try:
            if not eq:
                raise ValueError
            out[name.strip()] = float(value)
        except ValueError:
            raise BattgenError(f"--set {item!r}: expected NAME=NUMBER") from None
    return out


def run(args: argparse.Namespace) -> int:
    conversion = Conversion(args.package, args.source, args.target, args.policy)
    extra = _inputs(args.set)
    for name in extra:
        if name not in conversion.inputs_taken:
            raise BattgenError(
                f"--set {name}: not an input of {conversion.source_name} -> {conversion.target_name} "
                f"({', '.join(conversion.inputs_taken) or 'none'})"
            )
    loss: Literal["entries", "summary"] | None = (
        "entries" if args.report else "summary" if args.report_summary else None
    )
    out_stream: IO[bytes] = open(args.output, "wb") if args.output else sys.stdout.buffer
    try:
        for path in args.files or ["-"]:
            fmt = input_format(path, args.in_format)
            out_fmt = output_format(fmt, args.out_format)
            source = sys.stdin.buffer if path == "-" else Path(path)
            where = "<stdin>" if path == "-" else path
            events = conversion.run(source, where, fmt, binary=out_fmt in ("hex", "raw"), loss=loss, inputs=extra)
            _write(events, where, fmt, out_fmt, out_stream)
    finally:
        if args.output:
            out_stream.close()
    return 0


def _write(events: Iterable[Converted | Notice], where: str, fmt: str, out_fmt: str, out: IO[bytes]) -> None:
    """Converted records to ``out`` in ``out_fmt`` (JSON Lines and binary as they come, JSON and
    YAML once the input is done); warning notices, and the loss of binary records, to stderr."""
    collected: list[Any] = []
    for event in events:
        if isinstance(event, Notice):
            if event.severity == "warning":
                print(f"{where}: warning: {event.message}", file=sys.stderr)
            continue
        if out_fmt in ("hex", "raw"):
            payloads = event.payloads
            out.write(b" ".join(p.hex().encode() for p in payloads) + b"\n" if out_fmt == "hex" else b"".join(payloads))
            if event.loss is not None:
                where_from = {"source": dict(event.source)} if event.source is not None else {"line": event.line}
                sys.stderr.write(json.dumps({**where_from, "loss": event.loss}) + "\n")
            continue
        record: Any = event.plain
        if event.loss is not None:
            record = {"record": event.plain, "loss": event.loss}
            if event.source is not None:  # a log record: which topic instance, when, where in the file
                record["source"] = dict(event.source)
        if out_fmt == "jsonl":
            out.write(json.dumps(record, allow_nan=False).encode() + b"\n")
            out.flush()
        else:
            collected.append(record)
    if out_fmt == "json":
        data = collected[0] if len(collected) == 1 and fmt == "json" else collected
        out.write(json.dumps(data, indent=2, allow_nan=False).encode() + b"\n")
    elif out_fmt == "yaml":
        data = collected[0] if len(collected) == 1 else collected
        out.write(yaml.safe_dump(data, sort_keys=False).encode())

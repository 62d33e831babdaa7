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

``--policy strict`` refuses (exit 2) a record ``battgen validate`` finds an error in, as validate judges the
input (a log's firmware profile, the fields a log lacks left out); no record validate accepts is refused: a
value the target cannot hold (a NaN cell among known ones in MAVLink's integer cells) is written as the
target's "unknown" with an ``unrepresentable`` loss entry; each such kind is one line on stderr naming file,
record and field, with a count, and the exit code is 1. An input without records is exit 1 too
(``--allow-empty`` accepts it).
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import IO, Any, Literal, cast

from ..apps.conversion.convert import FORMATS, LOG_FORMATS, Conversion, Converted, input_format, output_format
from ..apps.conversion.jsonlines import encode_record
from ..apps.conversion.senders import SENDERS
from ..errors import BattgenError, missing_file
from ..inputs.model import MessageClass
from ..inputs.records import Notice
from ..text.escape import line
from .cyphal_options import add_cyphal_subject, check_subjects


def register(subparsers: Any, summary: str) -> None:
    p = subparsers.add_parser("convert", help=summary)
    p.add_argument("--from", dest="source", required=True, help="source side (dronecan, uorb, uorb_v0, mavlink, ...)")
    p.add_argument("--to", dest="target", required=True, help="target side, or 'concepts' for the shared state")
    p.add_argument(
        "--policy",
        choices=("strict", "px4", "ardupilot"),
        default="strict",
        help="strict (default), px4 or ardupilot: as the specifications say, or as that firmware's code does",
    )
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
    p.add_argument(
        "--sender",
        choices=sorted(SENDERS),
        help="the device that sent the input, read as its firmware means its values (nxp-bms772: NXP's BMS sends "
        "temperatures as degrees Celsius + 272.15); each corrected value is in the loss report",
    )
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help="extra converter input (number)")
    p.add_argument(
        "--package", help="a generated package to use, by import name (default: the one installed with battgen)"
    )
    p.add_argument(
        "--allow-empty", action="store_true", help="an input without records is not an error (default: exit 1)"
    )
    add_cyphal_subject(p)
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
    for given in args.files:  # a missing file said first, before what its name would make of it (a .dts's side)
        if given != "-" and not Path(given).exists():
            raise missing_file(given)
    conversion = Conversion(args.package, args.source, args.target, args.policy, args.cyphal_subject, args.sender)
    first = conversion.source.items[0][1]
    if isinstance(first, MessageClass):
        check_subjects(args.cyphal_subject, first)
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
    out_stream: IO[bytes] = open_output(args.output) if args.output else sys.stdout.buffer
    tally = Tally()
    try:
        for path in args.files or ["-"]:
            fmt = input_format(path, args.in_format)
            out_fmt = output_format(fmt, args.out_format)
            source = sys.stdin.buffer if path == "-" else Path(path)
            where = "<stdin>" if path == "-" else path
            binary, lines = out_fmt in ("hex", "raw"), out_fmt == "jsonl"
            events = conversion.run(source, where, fmt, binary=binary, loss=loss, inputs=extra, lines=lines)
            before = tally.records
            _write(tally.count(events, where), where, fmt, out_fmt, out_stream, streaming=path == "-")
            if tally.records == before:
                # a DataFlash log without logged CAN frames is most likely a flight log given for its BAT records
                log = " (an ArduPilot DataFlash log: convert reads its CANF/CAFD CAN frames, and it has none)"
                tally.empty.append(where + (log if fmt == "dataflash" else ""))
    finally:
        if args.output:
            out_stream.close()
    return tally.finish(conversion.target_name, allow_empty=args.allow_empty)


def open_output(name: str) -> IO[bytes]:
    """The -o file, opened for writing; a clear one-line error for a missing folder or a folder."""
    path = Path(name)
    if path.is_dir():
        raise BattgenError(f"-o {name}: is a folder; expected a file name")
    if not path.parent.is_dir():
        raise BattgenError(f"-o {name}: the folder {path.parent.as_posix()} does not exist")
    try:
        return path.open("wb")
    except OSError as exc:
        raise BattgenError(f"-o {name}: cannot write: {exc.strerror or exc}") from None


class Tally:
    """What a run converted: records, inputs without any, and the values the target could not
    hold (grouped by field and detail, with the count and the first record)."""

    def __init__(self) -> None:
        self.records = 0
        self.empty: list[str] = []
        self.unheld: dict[tuple[str, str], list[object]] = {}  # (field, detail) -> [count, first source]

    def count(self, events: Iterable[Converted | Notice], where: str) -> Iterable[Converted | Notice]:
        for event in events:
            if isinstance(event, Converted):
                self.records += 1
                for key in event.unrepresentable:
                    seen = self.unheld.setdefault(key, [0, event.source or {"file": where}])
                    seen[0] = cast(int, seen[0]) + 1
            yield event

    def finish(self, target: str, *, allow_empty: bool) -> int:
        """Print the closing lines on stderr; the exit code: 1 for an input without records
        (unless allowed) or values the target could not hold, else 0."""
        code = 0
        for where in self.empty:
            if not allow_empty:
                print(line(f"{where}: no records to convert (--allow-empty accepts that)"), file=sys.stderr)
                code = 1
        for (field, detail), (n, first) in self.unheld.items():
            at = _where(cast(Mapping[str, object], first))
            times = f" ({n} records, the first shown)" if cast(int, n) > 1 else ""
            print(line(f"{at}: {field}: {detail}{times}"), file=sys.stderr)
        if self.unheld:
            records = sum(cast(int, v[0]) for v in self.unheld.values())
            print(
                f"convert: {self.records} records to {target}; {len(self.unheld)} kinds of value the target cannot "
                f"hold, written as its 'unknown' ({records} times; --report lists each record's losses)",
                file=sys.stderr,
            )
            code = 1
        return code


def _where(source: Mapping[str, object]) -> str:
    """``file: record N (topic multi_id M, timestamp T us, offset O)`` or ``file:line: record N``."""
    file = str(source.get("file", ""))
    head = f"{file}:{source['line']}" if "line" in source else file
    text = f"{head}: record {source['record']}" if "record" in source else head
    if "topic" in source:
        stamp = f", timestamp {source['timestamp_us']} us" if source.get("timestamp_us") is not None else ""
        text += f" ({source['topic']} multi_id {source['multi_id']}{stamp}, offset {source['offset']})"
    return text


def _write(
    events: Iterable[Converted | Notice], where: str, fmt: str, out_fmt: str, out: IO[bytes], *, streaming: bool = True
) -> None:
    """Converted records to ``out`` in ``out_fmt`` (JSON Lines and binary as they come, JSON and
    YAML once the input is done); warning notices, and the loss of binary records, to stderr.
    ``streaming`` (standard input): each JSON Lines record is flushed as it is written, for a reader at
    the other end of a pipe; a file's records are written through the buffer."""
    collected: list[Any] = []
    for event in events:
        if isinstance(event, Notice):
            if event.severity == "warning":
                print(line(f"{where}: warning: {event.message}"), file=sys.stderr)
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
            if event.source is not None:  # the file, the record, and a log record's topic instance
                record["source"] = dict(event.source)
        if out_fmt == "jsonl":
            # json.dumps(record, allow_nan=False)'s bytes: made with the record, else here
            out.write(event.text if event.text is not None else encode_record(record))
            if streaming:
                out.flush()
        else:
            collected.append(record)
    if out_fmt == "json":
        data = collected[0] if len(collected) == 1 and fmt == "json" else collected
        out.write(json.dumps(data, indent=2, allow_nan=False).encode() + b"\n")
    elif out_fmt == "yaml":
        import yaml  # only for YAML output: a JSON Lines run does without it

        data = collected[0] if len(collected) == 1 else collected
        out.write(yaml.safe_dump(data, sort_keys=False).encode())

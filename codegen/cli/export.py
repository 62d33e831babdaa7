"""``battgen export LOG... -o DIR``: battery records of many logs into one Parquet dataset.

Inputs: PX4 ULog (.ulg), MAVLink telemetry logs (.tlog), ArduPilot DataFlash logs (.bin: BAT
readings), CAN captures (candump .log, .asc, .blf, .trc, also .gz or .xz: DroneCAN BatteryInfo with
BatteryInfoAux, and CUAV CBAT, per node) and JSON Lines (.jsonl/.ndjson) of any
bundled battery message (``--message``, else told from the first record's keys); a folder stands
for the logs under it. Every record becomes a row of one table in SI units, unknown values null,
partitioned by log (``DIR/battery/log=<id>/``); ``--raw`` also writes each message's own table.
A log already in the dataset (same content) is skipped; a log that cannot be read is reported at
the end and the run goes on. Exit 0 when every log was exported or skipped, 1 when some failed or
had records left out (a battery number its type cannot hold: each said on stderr), 2 when there is
nothing to read or the fleet extra is missing.

``--failsafe PARAMS`` also replays each flight log (.ulg, .tlog, .bin) through its firmware's battery
failsafe as ``battgen failsafe`` does and chooses (``--firmware``; else ArduPilot's for ArduPilot's BATT*_
parameters, PX4's for PX4's or for a ULog), with the parameter file PARAMS (``--failsafe log``: each
log's own parameters), into ``DIR/failsafe/log=<id>/``; a log exported before without that replay is
exported again.

``--engine dask`` runs the same per-log export as tasks on a Dask cluster (``--scheduler
ADDRESS``, else a local one with ``--jobs`` workers); the output folder must be reachable by
every worker under the same path.

A log becomes visible in one step, the rename of its marker (``DIR/logs/<id>.json``) naming its files;
a re-export writes a new version beside the old and removes the old after that rename. A run stopped
at any moment leaves each log old or new, and the next run removes what it left. One export writes a
dataset at a time: a second waits, saying which process holds it. An unreadable ``DIR/dataset.json``
is refused (exit 2), never replaced by defaults.
"""

from __future__ import annotations

import argparse
import re
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..errors import BattgenError
from ..text.escape import line
from .cyphal_options import add_cyphal_subject, check_bundled_subjects

EXIT_OK, EXIT_FAILED, EXIT_UNREADABLE = 0, 1, 2
_SUFFIXES = (".ulg", ".tlog", ".bin", ".jsonl", ".ndjson", ".asc", ".blf", ".trc")


def register(subparsers: Any, summary: str) -> None:
    p = subparsers.add_parser(
        "export",
        help=summary,
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "logs", nargs="+", metavar="LOG", help="log files (.ulg, .tlog, .bin, .jsonl, CAN captures) or folders of them"
    )
    p.add_argument("-o", "--out", required=True, metavar="DIR", help="the dataset folder (created if needed)")
    p.add_argument("--raw", action="store_true", help="also write each message's table, fields as decoded")
    p.add_argument("--message", help="the message of JSON Lines inputs (default: told from their keys)")
    add_cyphal_subject(p)
    p.add_argument(
        "--failsafe",
        metavar="PARAMS",
        help="replay every log through its firmware's battery failsafe (as battgen failsafe chooses it) with this "
        "parameter file, or 'log' for each log's own parameters (events in DIR/failsafe/, summed up in the flights "
        "view)",
    )
    p.add_argument("--vehicle", help="--failsafe: the ArduPilot vehicle (default: detected from the parameters)")
    p.add_argument(
        "--firmware",
        choices=("px4", "ardupilot"),
        help="--failsafe: whose failsafe (default: the parameters', else the log's: PX4's for a ULog)",
    )
    p.add_argument(
        "--partition",
        choices=("log", "day"),
        default="log",
        help="Hive partitions by log (default) or by UTC day then log (day=YYYY-MM-DD/log=<id>)",
    )
    p.add_argument("--jobs", type=int, default=1, metavar="N", help="logs exported in N processes (1)")
    p.add_argument("--engine", choices=("local", "dask"), default="local", help="local processes or a Dask cluster")
    p.add_argument("--scheduler", metavar="ADDRESS", help="the Dask scheduler (default: a local cluster)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar, no summary")
    p.add_argument("--allow-empty", action="store_true", help="a log without battery records is not an error")
    p.set_defaults(func=run)


def _inputs(names: list[str]) -> list[str]:
    out: list[str] = []
    for name in names:
        path = Path(name)
        if path.is_dir():
            out.extend(sorted(p.as_posix() for p in path.rglob("*") if _exportable(p)))
        else:
            out.append(name)
    return out


def _exportable(path: Path) -> bool:
    """A file of a folder to export: by its extension; a ``.log`` (``.log.gz``, ``.log.xz``) only when it reads
    as a candump capture, ``(seconds) interface id#data`` (a folder of logs holds other text logs too)."""
    from ..inputs.can.bounded import opened  # imported here: the CLI's start stays light
    from ..inputs.files.kinds import COMPRESSED_SUFFIXES

    suffixes = [x.lower() for x in path.suffixes[-2:]]
    if not path.is_file():
        return False
    if suffixes[-1:] and suffixes[-1] in COMPRESSED_SUFFIXES:
        suffixes = suffixes[:-1]
    if suffixes[-1:] != [".log"]:
        return path.suffix.lower() in _SUFFIXES or bool(suffixes and suffixes[-1] in _SUFFIXES)
    try:
        with opened(path) as f:
            head = f.read(64)
    except (OSError, EOFError, ValueError):  # a damaged stream (zlib.error, LZMAError are not OSErrors)
        return True  # let the export report it
    return bool(re.match(rb"\(\d+(\.\d+)?\) \S+ [0-9A-Fa-f]+#", head))


def _progress(total: int, quiet: bool) -> tuple[Callable[[Any], None] | None, Callable[[], None]]:
    """A tqdm bar on a terminal (stderr), else nothing."""
    if quiet or total < 2 or not sys.stderr.isatty():
        return None, lambda: None
    try:
        from tqdm import tqdm
    except ImportError:
        return None, lambda: None
    bar = tqdm(total=total, unit="log", file=sys.stderr)

    def step(result: Any) -> None:
        bar.update(1)

    return step, bar.close


def _failsafe_options(args: argparse.Namespace) -> Any:
    """``--failsafe``'s replay options (the replay is imported by the runs that ask for it)."""
    from ..apps.export.failsafe_tables import failsafe_options

    return failsafe_options(args.failsafe, args.vehicle, args.firmware)


def _tell(text: str) -> None:
    print(line(f"battgen: {text}"), file=sys.stderr)


def run(args: argparse.Namespace) -> int:
    try:
        from ..apps.export import engine
    except ImportError as exc:
        print(
            f"battgen: export needs the fleet extra ({exc.name} is missing): pip install 'battgen[fleet]'",
            file=sys.stderr,
        )
        return EXIT_UNREADABLE
    if Path(args.out).exists() and not Path(args.out).is_dir():
        print(line(f"battgen: -o {args.out}: is a file; expected a folder for the dataset"), file=sys.stderr)
        return EXIT_UNREADABLE
    logs = _inputs(args.logs)
    if not logs:
        print("battgen: no logs to export (expected .ulg, .tlog, .bin, .jsonl or CAN capture files)", file=sys.stderr)
        return EXIT_UNREADABLE
    if args.jobs < 1:
        print("battgen: --jobs must be at least 1", file=sys.stderr)
        return EXIT_UNREADABLE
    if args.firmware is not None and args.failsafe is None:
        print("battgen: --firmware is the failsafe replay's: give --failsafe PARAMS too", file=sys.stderr)
        return 2
    if args.vehicle is not None and args.failsafe is None:
        print("battgen: --vehicle is the failsafe replay's: give --failsafe PARAMS too", file=sys.stderr)
        return EXIT_UNREADABLE
    try:
        check_bundled_subjects(args.cyphal_subject)
    except BattgenError as exc:
        print(line(f"battgen: --cyphal-subject: {exc}"), file=sys.stderr)
        return EXIT_UNREADABLE
    try:
        replay = None if args.failsafe is None else _failsafe_options(args)
    except BattgenError as exc:
        print(line(f"battgen: --failsafe: {exc}"), file=sys.stderr)
        return EXIT_UNREADABLE
    options = engine.ExportOptions(
        Path(args.out),
        raw=args.raw,
        message=args.message,
        failsafe=replay,
        partition=args.partition,
        cyphal_subjects=tuple(args.cyphal_subject),
    )
    step, close = _progress(len(logs), args.quiet)
    try:
        if args.engine == "dask":
            from ..apps.export import distributed

            results = distributed.export_dask(logs, options, scheduler=args.scheduler, workers=args.jobs, progress=step)
        else:
            results = engine.export_logs(logs, options, jobs=args.jobs, progress=step, on_wait=_tell)
        engine.finish(options.out, on_wait=_tell)
    except ImportError as exc:
        print(
            f"battgen: the Dask engine needs dask.distributed ({exc.name} is missing): pip install 'battgen[fleet]'",
            file=sys.stderr,
        )
        return EXIT_UNREADABLE
    except BattgenError as exc:
        print(line(f"battgen: {exc}"), file=sys.stderr)
        return EXIT_UNREADABLE
    except OSError as exc:  # the dataset folder, not a log: a log's own errors are in its result
        print(line(f"battgen: {exc.filename or args.out}: cannot write: {exc.strerror or exc}"), file=sys.stderr)
        return EXIT_UNREADABLE
    finally:
        close()
    failed = [r for r in results if r.status == "failed"]
    for r in results:
        if r.replaced:
            print(
                line(f"battgen: {r.path}: replaces log {r.replaced}, its earlier export (the file has grown)"),
                file=sys.stderr,
            )
    for warning in (w for r in results for w in r.warnings):
        print(line(f"battgen: warning: {warning}"), file=sys.stderr)
    for r in failed:
        print(line(f"battgen: skipped {r.error}"), file=sys.stderr)
    # a log read without one battery record is not success (the README's rule for every command)
    empty = [r for r in results if r.status == "exported" and not r.rows]
    for r in empty if not args.allow_empty else ():
        print(
            line(f"battgen: {r.path}: expected battery records, found none (--allow-empty accepts that)"),
            file=sys.stderr,
        )
    if not args.quiet:
        rows = sum(r.rows for r in results)
        done, skipped = engine.count(results, "exported"), engine.count(results, "skipped")
        print(
            line(
                f"{len(results)} logs: {done} exported ({rows} rows), {skipped} already in the dataset, "
                f"{len(failed)} unreadable -> {args.out}"
            ),
            file=sys.stderr,
        )
    return EXIT_FAILED if failed or any(r.warnings for r in results) or (empty and not args.allow_empty) else EXIT_OK

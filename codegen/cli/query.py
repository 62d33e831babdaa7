"""``battgen query DIR "SQL"``: SQL over an exported dataset with DuckDB.

The dataset's ``battery`` table (every record, SI units, unknown as null) and the views:
``flights`` (per log and battery: duration, duration armed, min voltage and min cell voltage,
peak current, charge and energy used, max cell imbalance, max temperature, internal resistance)
and ``packs`` (per pack serial, else per vehicle and battery: flights, cycles, capacity used,
state of health, internal resistance). ``DIR/views.sql`` holds the same views for any DuckDB.

``--format table`` (default) prints aligned columns; ``csv`` and ``json`` (an array of objects)
go to standard output or ``-o FILE``; ``parquet`` needs ``-o FILE``. Exit 0, or 2 when the dataset
cannot be read, the SQL fails or DuckDB is missing.

Text from the logs (a ``sys_uuid``, a file name) is printed safely: in table and CSV form a control
character shows as ``\\xNN``, and a CSV text cell that begins with ``=``, ``+``, ``-``, ``@``, a tab or a
CR gets a leading single quote so that no spreadsheet takes it for a formula (OWASP's CSV injection
guard). ``--csv-raw`` writes the CSV cells exactly as the dataset holds them, for a program to read.
"""

from __future__ import annotations

import argparse
import csv
import datetime
import io
import json
import math
import sys
from pathlib import Path
from typing import Any

from ..errors import BattgenError
from ..text.escape import csv_cell, line, shown

EXIT_OK, EXIT_UNREADABLE = 0, 2
MAX_CELL = 40  # characters of one value in the table format


def register(subparsers: Any, summary: str) -> None:
    p = subparsers.add_parser(
        "query",
        help=summary,
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("dataset", metavar="DIR", help="a folder written by battgen export")
    p.add_argument("sql", metavar="SQL", help='e.g. "SELECT * FROM flights"')
    p.add_argument("--format", choices=("table", "csv", "json", "parquet"), default="table")
    p.add_argument("-o", "--out", metavar="FILE", help="write the result here (required for parquet)")
    p.add_argument(
        "--csv-raw",
        action="store_true",
        help="CSV cells as the dataset holds them: no quote before a leading = + - @, control characters kept",
    )
    p.set_defaults(func=run)


def _plain(value: Any) -> Any:
    if isinstance(value, datetime.datetime | datetime.date):
        return value.isoformat()
    if isinstance(value, float) and not math.isfinite(value):
        return None if math.isnan(value) else str(value)
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, bytes):
        return value.hex()
    return value


def _cell(value: Any) -> str:
    text = "" if value is None else json.dumps(_plain(value)) if isinstance(value, list | dict) else str(_plain(value))
    text = shown(text)
    return text if len(text) <= MAX_CELL else text[: MAX_CELL - 1] + "…"


def _csv_value(value: Any, raw: bool) -> Any:
    """A CSV cell: JSON for a list or struct; text guarded by :func:`csv_cell` unless ``raw`` (numbers are
    never guarded, infinities included: a negative current is data, not a formula)."""
    plain = json.dumps(_plain(value)) if isinstance(value, list | dict) else _plain(value)
    return csv_cell(plain) if isinstance(value, str) and not raw else plain


def table_text(columns: list[str], rows: list[tuple[Any, ...]]) -> str:
    cells = [[_cell(v) for v in row] for row in rows]
    columns = [shown(c) for c in columns]
    widths = [max([len(c)] + [len(r[i]) for r in cells]) for i, c in enumerate(columns)]
    lines = ["  ".join(c.ljust(w) for c, w in zip(columns, widths, strict=True)).rstrip()]
    lines.append("  ".join("-" * w for w in widths))
    lines.extend("  ".join(v.ljust(w) for v, w in zip(r, widths, strict=True)).rstrip() for r in cells)
    lines.append(f"({len(rows)} rows)")
    return "\n".join(lines) + "\n"


def run(args: argparse.Namespace) -> int:
    try:
        from ..apps.export import query as fleet_query
    except ImportError as exc:
        print(
            f"battgen: query needs the fleet extra ({exc.name} is missing): pip install 'battgen[fleet]'",
            file=sys.stderr,
        )
        return EXIT_UNREADABLE
    dataset = Path(args.dataset)
    try:
        if args.format == "parquet":
            if not args.out:
                raise BattgenError("--format parquet needs -o FILE")
            rows = fleet_query.query_to_parquet(dataset, args.sql, Path(args.out))
            print(line(f"{rows} rows -> {args.out}"), file=sys.stderr)
            return EXIT_OK
        result = fleet_query.run_query(dataset, args.sql)
    except BattgenError as exc:
        print(line(f"battgen: {exc}"), file=sys.stderr)
        return EXIT_UNREADABLE
    if args.format == "csv":
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        writer.writerow(result.columns if args.csv_raw else [csv_cell(c) for c in result.columns])
        writer.writerows([[_csv_value(v, args.csv_raw) for v in r] for r in result.rows])
        text = buf.getvalue()
    elif args.format == "json":
        text = (
            json.dumps([dict(zip(result.columns, map(_plain, r), strict=True)) for r in result.rows], indent=1) + "\n"
        )
    else:
        text = table_text(result.columns, result.rows)
    if args.out:
        try:
            Path(args.out).write_text(text, encoding="utf-8")
        except OSError as exc:
            print(line(f"battgen: {args.out}: cannot write: {exc.strerror or exc}"), file=sys.stderr)
            return EXIT_UNREADABLE
    else:
        sys.stdout.write(text)
    return EXIT_OK

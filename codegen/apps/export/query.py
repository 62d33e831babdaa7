"""The engine of ``battgen query``: DuckDB over an exported dataset, with the table ``battery``
and the fleet views (:mod:`codegen.apps.export.views`)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ...errors import BattgenError
from .dataset import BATTERY, layout
from .manifest import committed
from .views import views_sql


@dataclass(frozen=True)
class QueryResult:
    columns: list[str]
    rows: list[tuple[Any, ...]]


def connect(dataset: Path) -> Any:
    """A DuckDB connection with ``battery`` and the views over the dataset at ``dataset``."""
    try:
        import duckdb
    except ImportError:
        raise BattgenError("battgen query needs DuckDB: pip install 'battgen[fleet]'") from None
    layout(dataset)  # an unreadable dataset.json is said so, before anything else
    if not committed(dataset)[BATTERY]:
        raise BattgenError(f"{dataset}: no exported logs (expected {BATTERY}/log=*/*.parquet; run battgen export)")
    con = duckdb.connect()
    con.execute(views_sql(dataset))
    return con


def run_query(dataset: Path, sql: str) -> QueryResult:
    """Run ``sql`` over the dataset; errors in the SQL are BattgenErrors."""
    import duckdb

    con = connect(dataset)
    try:
        cur = con.execute(sql)
        columns = [d[0] for d in cur.description or []]
        return QueryResult(columns, cur.fetchall() if columns else [])
    except duckdb.Error as exc:
        raise BattgenError(f"query failed: {_one_line(exc)}") from None
    finally:
        con.close()


def query_to_parquet(dataset: Path, sql: str, out: Path) -> int:
    """Write the result of ``sql`` to a Parquet file; the number of rows."""
    import duckdb

    con = connect(dataset)
    try:
        target = out.as_posix().replace("'", "''")
        con.execute(f"COPY ({sql}) TO '{target}' (FORMAT parquet)")
        row = con.execute(f"SELECT count(*) FROM read_parquet('{target}')").fetchall()[0]
        return int(row[0])
    except duckdb.Error as exc:
        raise BattgenError(f"query failed: {_one_line(exc)}") from None
    finally:
        con.close()


def _one_line(exc: Exception) -> str:
    """DuckDB's message on one line: its sentences joined, the echo of the query and its caret line left out (the
    user has the query; a multi-line message would print as escaped line breaks)."""
    lines = [x.strip() for x in str(exc).splitlines()]
    kept = [x for x in lines if x and not x.startswith("LINE ") and set(x) != {"^"}]
    return "; ".join(kept) or type(exc).__name__

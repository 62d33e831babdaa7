"""What a dataset holds: each exported log's marker (``logs/<id>.json``) names the files of its committed
version, and readers read those files only.

A log's files are immutable and carry their version in their name (``part-<version>.parquet``,
``events-<version>.parquet``); a new version is written beside the old one, and the rename of the marker
that names it is the one step that makes it visible (as Delta Lake's log or Iceberg's snapshot swap do). A
writer killed at any point leaves the old marker (the old version) or the new one (the new version),
plus files no marker names; :func:`sweep` removes those at the next run's start, under the writers' lock.

Markers written before versions existed name no files: their log's files are the fixed names of that
time (``part-0.parquet``, ``events.parquet``, ``replays.parquet``) in the log's partition.
"""

from __future__ import annotations

import json
import re
import shutil
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from .durable import TMP_PREFIX

BATTERY = "battery"
RAW = "raw"
LOGS = "logs"
# the failsafe replay's table folder and files (:mod:`.failsafe_tables`), named here so that reading a dataset's
# layout does not import the replay (and, through it, the failsafe's parameter checks and schema loader)
FAILSAFE = "failsafe"
EVENTS_FILE = "events.parquet"
REPLAYS_FILE = "replays.parquet"
TABLE_FOLDERS = (BATTERY, RAW, FAILSAFE)
# the keys of a marker's "files": the battery table, the raw tables, the failsafe replay's two tables
FILE_KEYS = (BATTERY, RAW, "events", "replays")


def marker(out: Path, log: str) -> Path:
    return out / LOGS / f"{log}.json"


def read_marker(out: Path, log: str) -> dict[str, Any] | None:
    """What the marker of an exported log records (None: not exported, or a marker unreadable or damaged --
    a re-export replaces it)."""
    try:
        data = json.loads(marker(out, log).read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return None
    if not isinstance(data, dict) or damage(out, log, data) is not None:
        return None
    return data


_PARTITION = re.compile(
    r"(day=(\d{4}-\d{2}-\d{2}|__HIVE_DEFAULT_PARTITION__)/)?log=([0-9A-Za-z_-]+)"
)  # .dataset.partition_of


def damage(out: Path, log: str, data: Mapping[str, Any]) -> str | None:
    """Why a marker cannot be trusted, or None. A marker is what the next run deletes and what readers read: one
    that names another log, a partition of another shape, or a file outside the dataset's tables or missing (a
    hand edit, a disk error) would make a run delete what is not its own or the views read a file that is not
    there, so it counts as no marker: the log is exported again when it is given again."""
    if data.get("log") != log:
        return f"names log {str(data.get('log'))[:40]!r}, not {log!r}"
    where = data.get("partition")
    if where is not None:
        shape = _PARTITION.fullmatch(where) if isinstance(where, str) else None
        if shape is None or shape.group(3) != log:
            return f"expected a partition log={log} or day=YYYY-MM-DD/log={log}, got {str(where)[:60]!r}"
    if "replaces" in data and not (
        isinstance(data["replaces"], str) and _PARTITION.fullmatch(f"log={data['replaces']}")
    ):
        return "expected the id of the log it replaces"
    files = data.get("files")
    if files is None and "version" not in data:
        return None  # a marker of before versions: its files have fixed names (:func:`marker_files`)
    if (
        not isinstance(files, dict)
        or not set(files) <= set(FILE_KEYS)
        or not all(isinstance(v, list) for v in files.values())
        or not files.get(BATTERY)
    ):
        return (
            f"expected its version's files as lists of paths by table ({', '.join(FILE_KEYS)}), a battery table first"
        )
    for names in files.values():
        for rel in names:
            if not (isinstance(rel, str) and _inside_tables(rel)):
                return f"expected a table file of the dataset, got {str(rel)[:80]!r}"
            try:
                present = (out / rel).is_file()
            except OSError:  # a name the file system refuses (too long): no file of ours
                present = False
            if not present:
                return f"names a file that is missing: {rel[:80]}"
    return None


def _inside_tables(rel: str) -> bool:
    parts = rel.split("/")
    return (
        len(parts) >= 3
        and parts[0] in TABLE_FOLDERS
        and all(p not in ("", ".", "..") and "\\" not in p and len(p) <= 255 for p in parts)
        and rel.endswith(".parquet")
    )


def _markers(out: Path) -> list[dict[str, Any]]:
    found = []
    for path in sorted((out / LOGS).glob("*.json")) if (out / LOGS).is_dir() else []:
        data = read_marker(out, path.stem)
        if data is not None:
            found.append(data)
    return found


def marker_files(out: Path, manifest: Mapping[str, Any]) -> dict[str, list[str]]:
    """The files of the version a marker names, relative to ``out``, by :data:`FILE_KEYS` key."""
    files = manifest.get("files")
    if isinstance(files, dict):
        return {str(k): [str(f) for f in v] for k, v in files.items() if isinstance(v, list)}
    where = str(manifest.get("partition") or f"log={manifest.get('log')}")  # a marker of before versions
    legacy = {
        BATTERY: [f"{BATTERY}/{where}/part-0.parquet"],
        "events": [f"{FAILSAFE}/{where}/{EVENTS_FILE}"],
        "replays": [f"{FAILSAFE}/{where}/{REPLAYS_FILE}"],
        RAW: sorted(p.relative_to(out).as_posix() for p in (out / RAW).glob(f"*/{where}/part-0.parquet")),
    }
    return {key: [f for f in names if (out / f).is_file()] for key, names in legacy.items()}


def _current(markers: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The markers of logs no other marker replaces (a log exported again once it grew: :func:`retire`)."""
    source = {str(m.get("log")): m.get("source") for m in markers}
    # a log replaces only an earlier export of the same source (it grew): a marker naming another's log, damaged
    # or crafted, must not hide (and have the next run delete) a flight that is not its own
    replaced = {
        str(m["replaces"]) for m in markers if m.get("replaces") and source.get(str(m["replaces"])) == m.get("source")
    }
    return [m for m in markers if str(m.get("log")) not in replaced]


def committed(out: Path) -> dict[str, list[str]]:
    """Every committed file of the dataset at ``out`` (relative paths, sorted), by :data:`FILE_KEYS` key."""
    files: dict[str, list[str]] = {key: [] for key in FILE_KEYS}
    for manifest in _current(_markers(out)):
        for key, names in marker_files(out, manifest).items():
            files.setdefault(key, []).extend(names)
    return {key: sorted(names) for key, names in files.items()}


def exported_sources(out: Path) -> tuple[tuple[str, str, int], ...]:
    """(source file name, log id, its size in bytes) of every current log whose marker records its size."""
    found = []
    for m in _current(_markers(out)):
        size = m.get("bytes")
        if isinstance(size, int) and isinstance(m.get("source"), str):
            found.append((str(m["source"]), str(m.get("log")), size))
    return tuple(found)


def retire(out: Path, log: str) -> None:
    """Remove a log that another's marker replaces: its marker first (the replacing marker already hides it
    from readers, so a stop in between changes nothing they see), then its files."""
    old = read_marker(out, log)
    if old is None:
        return
    marker(out, log).unlink(missing_ok=True)
    for names in marker_files(out, old).values():
        for rel in names:
            (out / rel).unlink(missing_ok=True)


def sweep(out: Path) -> int:
    """Remove what writers stopped before their commit left: temporary folders and files (``.tmp-*``) and
    table files no marker names. Only under the writers' lock. Returns how many were removed."""
    removed = 0
    for folder in (out, out / LOGS):
        for path in folder.glob(f"{TMP_PREFIX}*") if folder.is_dir() else []:
            if path.is_dir():
                shutil.rmtree(path, ignore_errors=True)
            else:
                path.unlink(missing_ok=True)
            removed += 1
    markers = _markers(out)
    for replaced in {str(m.get("log")) for m in markers} - {str(m.get("log")) for m in _current(markers)}:
        retire(out, replaced)  # a run stopped between a grown log's commit and the removal of what it replaced
        removed += 1
    keep = {name for names in committed(out).values() for name in names}
    for table in TABLE_FOLDERS:
        for path in (out / table).rglob("*.parquet") if (out / table).is_dir() else []:
            if path.relative_to(out).as_posix() not in keep:
                path.unlink(missing_ok=True)
                removed += 1
    return removed

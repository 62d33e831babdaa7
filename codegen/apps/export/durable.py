"""File-system steps a crash cannot leave half done: a file written whole or not at all, data on disk
before the rename that publishes it, and one writer at a time on a dataset.

A rename (``os.replace``) is atomic on POSIX file systems, but only of what has reached the disk: without
an ``fsync`` of the file before it and of the folder after it, a power cut can leave the new name on an
empty file (ext4's "zero-length file" after a crash). Every file that makes something visible -- a log's
marker, ``dataset.json``, ``views.sql`` -- is written through :func:`write_atomic`.
"""

from __future__ import annotations

import fcntl
import os
import secrets
import socket
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

TMP_PREFIX = ".tmp-"  # what a writer leaves while it works: removed at the next run's start
LOCK_FILE = ".battgen-export.lock"


def fsync_file(path: Path) -> None:
    """``path``'s data on disk."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def fsync_dir(path: Path) -> None:
    """The entries of folder ``path`` (a rename or a new file in it) on disk."""
    fd = os.open(path, os.O_RDONLY | os.O_DIRECTORY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def write_atomic(path: Path, text: str) -> None:
    """``path`` holds ``text`` or what it held before, whatever happens: a temporary file beside it (named
    so that no ``*.json`` glob takes it), fsynced, renamed over it, the folder fsynced."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.parent / f"{TMP_PREFIX}{path.name}.{secrets.token_hex(4)}"
    try:
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    fsync_dir(path.parent)


@contextmanager
def writers_lock(out: Path, on_wait: Callable[[str], None] | None = None) -> Iterator[None]:
    """Hold the dataset at ``out`` for one writer (``fcntl.flock`` on a lock file in it): a second export
    waits, told through ``on_wait`` who holds it. The lock goes with the process, so a killed writer
    never leaves the dataset locked. (flock is local to one machine on some network file systems: a
    Dask cluster's workers write under the lock their client holds.)"""
    out.mkdir(parents=True, exist_ok=True)
    fd = os.open(out / LOCK_FILE, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 200, 0).decode("utf-8", "replace").strip() or "another process"
            if on_wait is not None:
                on_wait(f"{out}: another export is writing this dataset ({holder}); waiting for it to finish")
            fcntl.flock(fd, fcntl.LOCK_EX)
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"pid {os.getpid()} on {socket.gethostname()}\n".encode(), 0)
        yield
    finally:
        os.close(fd)  # releases the lock

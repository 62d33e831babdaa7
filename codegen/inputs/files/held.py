"""A log held still while it is read: a file that another program truncates or rewrites in place
under a memory map kills the reader with SIGBUS (no exception, no message), and the readers map
logs (the ULog reader, pymavlink's DataFlash reader).

Linux has the tool for this: a read lease (``fcntl(F_SETLEASE, F_RDLCK)``). While it is held, a
program that opens the file for writing or truncates it is made to wait (up to
``/proc/sys/fs/lease-break-time``, 45 s by default) and this process is sent SIGIO. The handler
here raises :class:`FileChanged` in the reading code, the read unwinds (releasing the lease on the
way out) and only then does the writer go on: the log is reported as changed while read, and
nothing of it is kept.

Where no lease can be had (another program already has the file open for writing, a file system
without leases, a file this user does not own, a thread other than the main one, not Linux),
:attr:`Hold.leased` is False and a reader that would map the file reads it into memory instead:
a file that shrinks then reads short, which the readers report as a truncated log.
"""

from __future__ import annotations

import contextlib
import fcntl
import mmap
import os
import signal
import threading
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from types import FrameType

from ..records import InputError

_SETLEASE: int = getattr(fcntl, "F_SETLEASE", -1)  # Linux only: -1 elsewhere, where nothing is leased
_GETLEASE: int = getattr(fcntl, "F_GETLEASE", -1)
_RDLCK, _UNLCK = fcntl.F_RDLCK, fcntl.F_UNLCK


Buffer = mmap.mmap | bytes  # a log's bytes: a read-only map of the file, or the file read whole


def whole(path: Path, name: str) -> bytes:
    """A file read into memory (where it cannot be held still, rather than mapped)."""
    try:
        return path.read_bytes()
    except OSError as exc:
        raise InputError(name, 0, f"cannot read file: {exc.strerror or exc}") from None


class FileChanged(InputError):
    """Another program opened a log for writing (or truncated it) while battgen read it."""

    def __init__(self, name: str) -> None:
        super().__init__(
            name, 0, "the file changed while it was read (another program opened it for writing): read it again"
        )


@dataclass
class Hold:
    """A file held for reading: ``leased`` tells whether writers wait for it (else read it whole
    rather than through a map)."""

    name: str
    fd: int | None = None
    changed: bool = False

    @property
    def leased(self) -> bool:
        return self.fd is not None


_held: dict[str, Hold] = {}  # path -> its hold: a nested hold of the same file is the outer one
_installed = False  # the SIGIO handler stays once set: a signal still pending when a hold ends must not kill


def _on_sigio(signum: int, frame: FrameType | None) -> None:
    """A lease being broken: raise in whatever the main thread reads, once per file."""
    for hold in _held.values():
        if hold.fd is None or hold.changed:
            continue
        try:
            breaking = fcntl.fcntl(hold.fd, _GETLEASE) != _RDLCK  # a lease being broken reports its target: unlocked
        except OSError:
            breaking = True
        if breaking:
            hold.changed = True
            raise FileChanged(hold.name)


def _lease(path: Path) -> int | None:
    """An fd of ``path`` carrying a read lease, or None where none can be had."""
    if _SETLEASE < 0 or threading.current_thread() is not threading.main_thread():
        return None
    try:
        fd = os.open(path, os.O_RDONLY | os.O_CLOEXEC)
    except OSError:
        return None  # the reader opens it and says why it cannot
    try:
        fcntl.fcntl(fd, _SETLEASE, _RDLCK)
    except OSError:  # EAGAIN: open for writing elsewhere; EACCES: not ours; EINVAL: no leases here
        os.close(fd)
        return None
    return fd


@contextlib.contextmanager
def held(path: Path, name: str) -> Iterator[Hold]:
    """Hold ``path`` still while the body reads it; raises :class:`FileChanged` (in the body, or at
    its end) if another program opens it for writing meanwhile."""
    global _installed
    key = os.path.abspath(path)
    outer = _held.get(key)
    if outer is not None:
        yield outer
        return
    hold = Hold(name)
    fd = _lease(path)
    if fd is not None:
        if not _installed:
            signal.signal(signal.SIGIO, _on_sigio)  # SIGIO's default is to terminate; battgen uses it for nothing else
            _installed = True
        hold.fd = fd
    _held[key] = hold
    try:
        yield hold
    finally:
        del _held[key]
        if fd is not None:
            with contextlib.suppress(OSError):
                fcntl.fcntl(fd, _SETLEASE, _UNLCK)  # a map of the file shares this fd's lease: unlock, not just close
            os.close(fd)
    if hold.changed:  # noticed by a reader that went on (a broad except): its result is not the file's
        raise FileChanged(name)

"""Naming a log by its content, and reading a ULog through one memory map for hashing and decoding."""

from __future__ import annotations

import hashlib
import math
import mmap
from pathlib import Path
from typing import Any

import xxhash

ID_DIGITS = 16


def content_id(path: Path, source: mmap.mmap | bytes | None = None, scheme: str = "xxh128") -> str:
    """The stable id of a file's content: the first hex digits of its XXH3-128 (``xxh128sum``'s),
    or of its SHA-256 (``sha256sum``'s) in a dataset made before battgen chose XXH3 (see
    :func:`.dataset.content_scheme`).

    Why not a cryptographic hash: an id of 16 hex digits (64 bits) has a 2^32 birthday bound
    whatever hash it is cut from, so SHA-256 or BLAKE3 would buy no collision resistance here, and
    they cost 10x and 5x XXH3's time: measured on a 171 MB log, SHA-256 0.10 s, BLAKE3 0.045 s,
    XXH3-128 0.010 s, of an export of about half a second. With ``source``, a memory map of the
    file, the hash reads the map: the pages the reader will use are mapped once."""
    return prefix_id(path, None, source, scheme)


def prefix_id(path: Path, size: int | None, source: mmap.mmap | bytes | None = None, scheme: str = "xxh128") -> str:
    """:func:`content_id` of the first ``size`` bytes of a file (None: all of it): the id an earlier, shorter copy
    of it had."""
    digest: Any = hashlib.sha256() if scheme == "sha256" else xxhash.xxh3_128()
    if source is not None:
        digest.update(source if size is None else memoryview(source)[:size])
        return str(digest.hexdigest())[:ID_DIGITS]
    left: float = math.inf if size is None else size
    with path.open("rb") as f:
        while left > 0:
            block = f.read(int(min(left, 1 << 20)))
            if not block:
                break
            digest.update(block)
            left -= len(block)
    return str(digest.hexdigest())[:ID_DIGITS]


def map_file(path: Path, held: bool = True) -> mmap.mmap | bytes | None:
    """A read-only memory map of a ULog file, for hashing and reading it in one pass (None for
    other kinds, and where a file cannot be mapped: empty, a pipe...); the file read whole where it
    is not ``held`` still (:mod:`...inputs.held_file`: a map of a file truncated meanwhile is a SIGBUS)."""
    if path.suffix.lower() != ".ulg":
        return None
    if not held:
        try:
            return path.read_bytes()
        except OSError:
            return None  # the reader opens it again and says why it cannot
    try:
        with path.open("rb") as f:
            return mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ)
    except (OSError, ValueError):
        return None

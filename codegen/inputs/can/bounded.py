"""Capture files handed to python-can's readers with their sizes checked first.

python-can trusts a capture's sizes: its BLF reader reads an object of whatever size the object's
header states (a 928-byte file asking for 4 GiB) and inflates a compressed container in one call
(a 509 KiB file inflating to 1.07 GB); its text readers take a line of any length (a 64 KiB
``.log.gz`` holding one endless line inflates to 416 MB). Here:

- text captures (candump ``.log``, ``.asc``, ``.trc``, gzip- or xz-compressed or not) reach the reader
  as lines of at most :data:`MAX_LINE` bytes;
- a compressed capture is inflated on the fly, a buffer at a time (never in one call), and an ``.xz`` one with
  the decoder's memory capped at :data:`MAX_XZ_MEMORY` (an xz header may ask for a 1.5 GiB dictionary);
- a BLF reaches the reader as a stream of the same objects in which each container is already
  inflated, by at most :data:`MAX_CONTAINER` bytes, and no object is larger than
  :data:`MAX_OBJECT`; BLF's own layout (a file header, then ``LOBJ`` objects padded to four
  bytes; a log container: compression method, then the size it inflates to) is read here, from
  the format, so python-can gets only checked bytes.

Memory then stays flat whatever a capture holds, and a file that breaks these bounds is an
InputError naming it and the place, never a MemoryError or a traceback.
"""

from __future__ import annotations

import _compression
import gzip
import io
import lzma
import struct
import zlib
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any, cast

from ..files.kinds import COMPRESSED_SUFFIXES
from ..records import InputError

MAX_LINE = 1 << 16  # bytes of one line of a text capture (candump's longest, an FD frame, is under 200)
MAX_OBJECT = 1 << 24  # bytes of one BLF object as stored (Vector's containers hold some 128 KiB)
MAX_CONTAINER = 1 << 24  # bytes one BLF container may inflate to
MAX_FILE_HEADER = 1 << 12  # bytes of a BLF file header (144 in every known version)
MAX_XZ_MEMORY = 1 << 27  # bytes the xz decoder may use: xz -9 (a 64 MiB dictionary) needs 65 MiB

_FILE_HEAD = struct.Struct("<4sL")  # signature "LOGG", header size
_OBJECT_HEAD = struct.Struct("<4sHHLL")  # "LOBJ", header size, header version, object size, object type
_CONTAINER_HEAD = struct.Struct("<H6xL4x")  # compression method, inflated size
_LOG_CONTAINER = 10
_NO_COMPRESSION, _ZLIB = 0, 2


def opened(path: Path) -> IO[bytes]:
    """The capture's bytes, inflated on the fly where it is gzip- or xz-compressed (by name, as python-can
    decides for ``.gz``). Both inflate a buffer at a time; lzma.open has no memory limit, so the xz stream is
    read through the standard library's own decompressing reader with the decoder's ``memlimit`` set."""
    suffix = path.suffix.lower()
    if suffix == ".gz":
        return cast(IO[bytes], gzip.open(path, "rb"))
    if suffix == ".xz":
        raw = path.open("rb")
        try:
            inflating = _compression.DecompressReader(
                raw, lzma.LZMADecompressor, trailing_error=lzma.LZMAError, memlimit=MAX_XZ_MEMORY
            )
            return cast(IO[bytes], _ClosingBuffer(inflating, raw))
        except BaseException:
            raw.close()
            raise
    return path.open("rb")


class _ClosingBuffer(io.BufferedReader):
    """A buffered reader of an inflating stream that also closes the file under it."""

    def __init__(self, inflating: io.RawIOBase, raw: IO[bytes]) -> None:
        super().__init__(inflating)
        self._file = raw

    def close(self) -> None:
        try:
            super().close()
        finally:
            self._file.close()


def inner_suffix(path: Path) -> str:
    """The suffix that names the capture's format: ``.log`` for ``x.log.gz`` or ``x.log.xz``."""
    suffixes = [s.lower() for s in path.suffixes]
    if suffixes[-1:] and suffixes[-1] in COMPRESSED_SUFFIXES and len(suffixes) > 1:
        return suffixes[-2]
    return suffixes[-1] if suffixes else ""


def _damaged(name: str, line: int, exc: BaseException) -> InputError:
    """A compressed capture whose stream is damaged, cut, or asks the decoder for too much memory."""
    if isinstance(exc, lzma.LZMAError) and "memory" in str(exc).lower():
        return InputError(name, line, f"an xz stream needing more than {MAX_XZ_MEMORY} bytes to decode")
    return InputError(name, line, f"a damaged compressed capture ({str(exc)[:160] or type(exc).__name__})")


# what inflating a damaged stream raises: gzip's BadGzipFile (an OSError), zlib.error, a cut stream's EOFError,
# lzma's LZMAError (memory limit, corrupt data)
_INFLATE_ERRORS = (OSError, EOFError, zlib.error, lzma.LZMAError)


class BoundedLines:
    """A text capture as python-can's text readers use a file: lines, each at most :data:`MAX_LINE` bytes."""

    def __init__(self, raw: IO[bytes], name: str) -> None:
        self._raw = raw
        self.name = name
        self.line = 0

    def __iter__(self) -> BoundedLines:
        return self

    def __next__(self) -> str:
        text = self.readline()
        if not text:
            raise StopIteration
        return text

    def readline(self, size: int = -1) -> str:
        try:
            data = self._raw.readline(MAX_LINE + 1)
        except _INFLATE_ERRORS as exc:
            raise _damaged(self.name, self.line + 1, exc) from None
        if len(data) > MAX_LINE and not data.endswith(b"\n"):
            raise InputError(self.name, self.line + 1, f"a line of more than {MAX_LINE} bytes: expected a CAN capture")
        self.line += 1
        return data.decode("utf-8", "replace")

    def read(self, size: int = -1) -> str:
        """What a reader reads at once (python-can reads lines; this keeps any other use bounded too)."""
        return "".join(self)

    @property
    def closed(self) -> bool:
        return bool(self._raw.closed)

    def close(self) -> None:
        self._raw.close()


class BoundedBlf:
    """A BLF file with its containers inflated and every size checked, read as python-can's BLF reader reads a
    file (``read(n)``)."""

    def __init__(self, raw: IO[bytes], name: str) -> None:
        self._raw = raw
        self.name = name
        self._chunks = self._objects()
        self._buffer = bytearray()
        self._inner_tail = b""
        self.objects = 0

    def read(self, size: int = -1) -> bytes:
        while size < 0 or len(self._buffer) < size:
            chunk = next(self._chunks, None)
            if chunk is None:
                break
            self._buffer += chunk
        if size < 0:
            size = len(self._buffer)
        out = bytes(self._buffer[:size])
        del self._buffer[:size]
        return out

    @property
    def closed(self) -> bool:
        return bool(self._raw.closed)

    def close(self) -> None:
        self._raw.close()

    def _read(self, size: int) -> bytes:
        try:
            return self._raw.read(size)
        except _INFLATE_ERRORS as exc:
            raise _damaged(self.name, 0, exc) from None

    def _exact(self, size: int, what: str) -> bytes:
        data = self._read(size)
        if len(data) != size:
            raise InputError(self.name, 0, f"BLF {what}: {len(data)} of {size} bytes: the file ends early")
        return data

    def _objects(self) -> Iterator[bytes]:
        head = self._exact(_FILE_HEAD.size, "file header")
        signature, header_size = _FILE_HEAD.unpack(head)
        if signature != b"LOGG" or not _FILE_HEAD.size <= header_size <= MAX_FILE_HEADER:
            raise InputError(self.name, 0, f"expected a BLF file (LOGG, a header of at most {MAX_FILE_HEADER} bytes)")
        yield head + self._exact(header_size - _FILE_HEAD.size, "file header")
        while True:
            base = self._read(_OBJECT_HEAD.size)
            if not base:
                return
            if len(base) < _OBJECT_HEAD.size:
                return  # a file cut within an object's header: python-can stops there too
            signature, head_size, version, size, kind = _OBJECT_HEAD.unpack(base)
            where = f"object {self.objects}"
            if signature != b"LOBJ" or not _OBJECT_HEAD.size <= size <= MAX_OBJECT:
                raise InputError(
                    self.name, 0, f"BLF {where}: expected LOBJ and a size of 16..{MAX_OBJECT} bytes, found {size}"
                )
            body = self._read(size - _OBJECT_HEAD.size)
            padding = self._read(size % 4)
            self.objects += 1
            if len(body) < size - _OBJECT_HEAD.size:
                return  # cut within its data: the frames before it stand
            if kind != _LOG_CONTAINER:
                yield base + body + padding
                continue
            inflated = self._inflate(body, where)
            if inflated is None:
                yield base + body + padding  # a method python-can warns about and skips
                continue
            self._check_inner(inflated, where)
            new_size = _OBJECT_HEAD.size + _CONTAINER_HEAD.size + len(inflated)
            yield (
                _OBJECT_HEAD.pack(b"LOBJ", head_size, version, new_size, kind)
                + _CONTAINER_HEAD.pack(_NO_COMPRESSION, len(inflated))
                + inflated
                + bytes(new_size % 4)
            )

    def _check_inner(self, data: bytes, where: str) -> None:
        """No object inside a container states a size of 0: python-can's reader moves on by an object's size,
        so it would read that one forever (found by the long fuzz run). An object's header may start in one
        container and end in the next, as python-can joins them: the last bytes of the one before are kept."""
        joined = self._inner_tail + data
        at = joined.find(b"LOBJ")
        while at >= 0:
            if joined[at + 8 : at + 12] == bytes(4):
                raise InputError(self.name, 0, f"BLF {where}: an object inside it states a size of 0 bytes")
            at = joined.find(b"LOBJ", at + 1)
        self._inner_tail = joined[-(_OBJECT_HEAD.size - 1) :]

    def _inflate(self, body: bytes, where: str) -> bytes | None:
        if len(body) < _CONTAINER_HEAD.size:
            raise InputError(self.name, 0, f"BLF {where}: a log container without its header")
        method, stated = _CONTAINER_HEAD.unpack_from(body)
        data = body[_CONTAINER_HEAD.size :]
        if method == _NO_COMPRESSION:
            return data
        if method != _ZLIB:
            return None
        if stated > MAX_CONTAINER:
            raise InputError(self.name, 0, f"BLF {where}: a container stating {stated} bytes (at most {MAX_CONTAINER})")
        inflater = zlib.decompressobj()
        try:
            out = inflater.decompress(data, MAX_CONTAINER + 1)
        except zlib.error as exc:
            raise InputError(self.name, 0, f"BLF {where}: a damaged compressed container ({exc})") from None
        if len(out) > MAX_CONTAINER or inflater.unconsumed_tail:
            raise InputError(self.name, 0, f"BLF {where}: a container inflating beyond {MAX_CONTAINER} bytes")
        return out


def bounded_reader(can: Any, path: Path, name: str) -> Any:
    """python-can's reader for a capture file, fed through the bounds above; None for a suffix read some other way
    (python-can's ``.csv``, left to ``can.LogReader``)."""
    suffix = inner_suffix(path)
    readers = {".log": "CanutilsLogReader", ".asc": "ASCReader", ".trc": "TRCReader"}
    if suffix == ".blf":
        return can.BLFReader(BoundedBlf(opened(path), name))
    if suffix in readers:
        return getattr(can, readers[suffix])(BoundedLines(opened(path), name))
    return None

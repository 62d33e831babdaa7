"""Captures whose sizes lie: inflation bombs, endless lines, headers asking for gigabytes, frames longer than
their kind carries, a clock that goes back. Each gives one clear error (or a warning) in bounded memory; and on
every real capture of the corpus the bounded readers give exactly python-can's frames."""

from __future__ import annotations

import gzip
import struct
import subprocess
import sys
import zlib
from pathlib import Path

import can
import pytest

from codegen.apps.can_capture import scan
from codegen.apps.package import bundled_package
from codegen.inputs.can.bounded import MAX_CONTAINER, MAX_LINE, bounded_reader
from codegen.inputs.can.captures import read_capture
from codegen.inputs.can.reassembly import Frame
from codegen.inputs.can.records import registry
from codegen.inputs.records import InputError
from tests.shared_data import require, shared

CAPTURES = shared("corpus", "realworld3b", "can")
_SUFFIXES = (".log", ".asc", ".blf", ".trc", ".gz")


def _frames(reader: can.io.generic.MessageReader) -> list[tuple[float, int, bytes, bool, bool, bool, bool]]:
    out = [
        (m.timestamp, m.arbitration_id, bytes(m.data), m.is_extended_id, m.is_fd, m.is_error_frame, m.is_remote_frame)
        for m in reader
    ]
    reader.stop()
    return out


def test_the_bounded_readers_give_python_cans_frames_on_every_real_capture() -> None:
    files = sorted(p for p in require(CAPTURES).iterdir() if p.suffix.lower() in _SUFFIXES)
    assert len(files) >= 15
    compared = 0
    for path in files:
        try:
            theirs = _frames(can.LogReader(str(path)))
        except Exception:
            with pytest.raises(InputError):
                list(read_capture(path, path.name))
            continue
        ours = _frames(bounded_reader(can, path, path.name))
        assert ours == theirs, path.name
        compared += 1
    assert compared >= 15


# -- BLF: a file header, then LOBJ objects; a log container holds compressed frames -----------------------------


def _blf(objects: list[bytes]) -> bytes:
    header = struct.pack("<4sLBBBBBBBBQQLL8H8H", b"LOGG", 144, *([0] * 8), 0, 0, len(objects), 0, *([0] * 16))
    return header + bytes(144 - len(header)) + b"".join(objects)


def _container(payload: bytes, stated: int, method: int = 2) -> bytes:
    body = struct.pack("<H6xL4x", method, stated) + payload
    size = 16 + len(body)
    return struct.pack("<4sHHLL", b"LOBJ", 16, 1, size, 10) + body + bytes(size % 4)


def _zeros_deflated(n: int) -> bytes:
    packer = zlib.compressobj(9)
    block = bytes(1 << 20)
    parts = [packer.compress(block) for _ in range(n >> 20)]
    return b"".join(parts) + packer.flush()


def test_a_blf_container_inflating_beyond_the_bound_is_refused(tmp_path: Path) -> None:
    bomb = tmp_path / "bomb.blf"
    bomb.write_bytes(_blf([_container(_zeros_deflated(2 * MAX_CONTAINER), 1000)]))
    assert bomb.stat().st_size < 100_000
    with pytest.raises(InputError, match="inflating beyond"):
        list(read_capture(bomb, "bomb.blf"))


def test_a_blf_object_asking_for_gigabytes_is_refused_before_it_is_read(tmp_path: Path) -> None:
    liar = tmp_path / "liar.blf"
    liar.write_bytes(_blf([struct.pack("<4sHHLL", b"LOBJ", 16, 1, 2**32 - 1, 10) + bytes(64)]))
    with pytest.raises(InputError, match=r"size of 16\.\.16777216 bytes, found 4294967295"):
        list(read_capture(liar, "liar.blf"))


def test_a_damaged_compressed_blf_container_is_one_error(tmp_path: Path) -> None:
    damaged = tmp_path / "damaged.blf"
    damaged.write_bytes(_blf([_container(b"\x78\x9c" + bytes(range(200)), 1000)]))
    with pytest.raises(InputError, match="damaged compressed container"):
        list(read_capture(damaged, "damaged.blf"))


def test_a_container_python_can_cannot_parse_is_one_error(tmp_path: Path) -> None:
    """A container whose frames hold no LOBJ where the next object should start: python-can raises its own
    BLFParseError (a bare Exception), which the reader reports as the capture's error (found by the data-layer
    fuzzer on a mutated real BLF; rebuilt here from the format)."""
    broken = tmp_path / "broken.blf"
    broken.write_bytes(_blf([_container(bytes(32), 32, method=0)]))
    with pytest.raises(InputError, match="cannot read the CAN capture after frame 0: Could not find next object"):
        list(read_capture(broken, "broken.blf"))


def test_a_hostile_line_is_quoted_briefly(tmp_path: Path) -> None:
    """python-can's complaint quotes the whole line; the error does not (the fuzzer's 5 KB timestamp)."""
    capture = tmp_path / "long.log"
    capture.write_text("9" * 5000 + "(1436992770.657995) can0 1E3081FD#230D007B0100009B\n", encoding="ascii")
    with pytest.raises(InputError) as err:
        list(read_capture(capture, "long.log"))
    assert err.value.line == 1 and "9999" not in str(err.value) and len(str(err.value)) < 400


def test_an_endless_line_in_a_gzip_capture_is_refused(tmp_path: Path) -> None:
    endless = tmp_path / "endless.log.gz"
    with gzip.open(endless, "wb") as f:
        for _ in range(64):
            f.write(b"A" * (1 << 20))
    with pytest.raises(InputError, match=f"a line of more than {MAX_LINE} bytes"):
        list(read_capture(endless, "endless.log.gz"))


# a fresh process whose only child is the command: its RUSAGE_CHILDREN peak is that command's alone (this test
# process has had other children, whose peaks it would report too)
_PEAK = """
import resource, subprocess, sys
done = subprocess.run(sys.argv[1:], capture_output=True, text=True)
sys.stderr.write(done.stderr)
print(done.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
"""


def test_the_bombs_stay_in_bounded_memory_through_the_cli(tmp_path: Path) -> None:
    """The whole command on each bomb: one line, exit 1 or 2, and a peak resident size far below what the bombs ask."""
    bomb = tmp_path / "bomb.blf"
    bomb.write_bytes(_blf([_container(_zeros_deflated(8 * MAX_CONTAINER), 1000)]))
    endless = tmp_path / "endless.log.gz"
    with gzip.open(endless, "wb") as f:
        for _ in range(256):
            f.write(b"A" * (1 << 20))
    for path in (bomb, endless):
        command = [sys.executable, "-c", _PEAK, sys.executable, "-m", "codegen", "can", str(path)]
        done = subprocess.run(command, capture_output=True, text=True, timeout=300)
        code, peak_kib = (int(x) for x in done.stdout.split())
        assert code in (1, 2), done.stderr
        assert len(done.stderr.strip().splitlines()) == 1 and "Traceback" not in done.stderr
        assert peak_kib < 300 * 1024, f"{path.name}: peak {peak_kib} KiB"


# -- frames and clocks ------------------------------------------------------------------------------------------


def test_a_classic_frame_longer_than_8_bytes_is_refused_at_its_line(tmp_path: Path) -> None:
    capture = tmp_path / "long.log"
    capture.write_text(
        "(1.000000) can0 1F00107D#0102030405060708\n(1.100000) can0 1F00107D#01020304050607080910111213\n"
    )
    with pytest.raises(InputError, match="frame 1: 13 data bytes: expected a classic CAN frame") as err:
        list(read_capture(capture, "long.log"))
    assert err.value.line == 2


def test_a_clock_going_back_is_a_warning_and_rates_count_its_forward_stretches() -> None:
    # one message type from node 10 at 10 Hz, with the capture's clock set back 71 s half way
    times = [0.0, 0.1, 0.2, 0.3, 0.4, -70.6, -70.5, -70.4, -70.3]
    frames = [Frame(i, t, (1 << 26) | (341 << 8) | 10, bytes([0, 0, 0, 0, 0, 0, 0, 0xC0 | i]), True, False, "can0")
              for i, t in enumerate(times)]  # fmt: skip
    report = scan(frames, "back.log", registry(bundled_package().__name__))
    assert report.counts["can-clock-back"] == 1
    assert report.severities["can-clock-back"] == "warning"
    assert report.duration == pytest.approx(0.7)
    (stream,) = report.streams.values()
    assert stream.count == 9 and stream.rate == pytest.approx(10.0)

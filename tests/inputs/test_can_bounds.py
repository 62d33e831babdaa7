"""Captures whose sizes lie: inflation bombs, endless lines, headers asking for gigabytes, frames longer than
their kind carries, a clock that goes back. Each gives one clear error (or a warning) in bounded memory; and on
every real capture of the corpus the bounded readers give exactly python-can's frames."""

from __future__ import annotations

import gzip
import lzma
import struct
import subprocess
import sys
import zlib
from pathlib import Path

import can
import pytest

from codegen.apps.can.capture import scan
from codegen.apps.schemas.package import bundled_package
from codegen.cli.main import main
from codegen.inputs.can.bounded import MAX_CONTAINER, MAX_LINE, MAX_XZ_MEMORY, bounded_reader
from codegen.inputs.can.captures import read_capture
from codegen.inputs.can.reassembly import Frame
from codegen.inputs.can.records import registry
from codegen.inputs.files.kinds import kind_of_name
from codegen.inputs.records import InputError
from tests.fuzz.measure import run_battgen
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


# -- xz: accepted wherever .gz is, inflated a buffer at a time with the decoder's memory capped ------------------


def _endless_xz(path: Path, mib: int) -> Path:
    """One line of ``mib`` MiB of "A", xz-compressed (some 10 KiB a hundred MiB)."""
    packer = lzma.LZMACompressor(preset=1)
    with path.open("wb") as f:
        for _ in range(mib):
            f.write(packer.compress(b"A" * (1 << 20)))
        f.write(packer.flush())
    return path


def _xz_asking_for(dictionary_code: int, data: bytes) -> bytes:
    """An xz stream of ``data`` whose block header states the LZMA2 dictionary of ``dictionary_code`` (40: 4 GiB),
    with the header's CRC32 made right again: what a hostile file can say, cheap to write."""
    packed = bytearray(lzma.compress(data, preset=0))
    start = 12  # after the stream header
    size = (packed[start] + 1) * 4
    header = packed[start : start + size]
    at = header.index(b"\x21\x01")  # filter id LZMA2, one byte of properties
    header[at + 2] = dictionary_code
    header[-4:] = zlib.crc32(bytes(header[:-4])).to_bytes(4, "little")
    packed[start : start + size] = header
    return bytes(packed)


def test_an_xz_capture_gives_the_frames_of_the_plain_one_for_every_real_capture(tmp_path: Path) -> None:
    files = sorted(p for p in require(CAPTURES).iterdir() if p.suffix.lower() in (".log", ".asc", ".blf", ".trc"))
    compared = set()
    for path in files:
        try:
            plain = list(read_capture(path, path.name))
        except InputError:
            continue
        packed = tmp_path / f"{path.name}.xz"
        packed.write_bytes(lzma.compress(path.read_bytes()))
        assert kind_of_name(packed) == "can"
        assert list(read_capture(packed, packed.name)) == plain, path.name
        compared.add(path.suffix.lower())
    assert compared == {".log", ".asc", ".blf", ".trc"}


def _battery_candump(cycles: int) -> bytes:
    """A candump -l capture of BatteryInfo transfers (three frames each) from node 20."""
    import dronecan
    from dronecan import transport

    info = dronecan.uavcan.equipment.power.BatteryInfo(voltage=16.0, current=5.0, state_of_charge_pct=80)
    lines = []
    for tid in range(cycles):
        transfer = transport.Transfer(payload=info, source_node_id=20, transfer_id=tid % 32, transfer_priority=30)
        for frame in transfer.to_frames():
            stamp = 1_700_000_000 + 0.001 * len(lines)
            lines.append(f"({stamp:.6f}) can0 {frame.message_id:08X}#{bytes(frame.bytes).hex().upper()}\n")
    return "".join(lines).encode("ascii")


def test_an_xz_capture_is_taken_by_every_command_that_takes_gz(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "logs"
    folder.mkdir()
    plain = tmp_path / "bus.log"
    plain.write_bytes(_battery_candump(20))
    packed = folder / "bus.log.xz"
    packed.write_bytes(lzma.compress(plain.read_bytes()))
    (folder / "notes.log.xz").write_bytes(lzma.compress(b"boot ok\n"))  # a text log, not a capture: left out
    for command in (["can"], ["validate"], ["convert", "--from", "dronecan", "--to", "uorb"]):
        assert main([*command, str(plain)]) == 0, command
        expected = capsys.readouterr().out.replace(str(plain), str(packed))
        assert main([*command, str(packed)]) == 0, command
        assert capsys.readouterr().out == expected, command
    assert main(["export", "-q", "-o", str(tmp_path / "ds"), str(folder)]) == 0
    out, err = capsys.readouterr()
    assert "notes" not in out + err
    assert main(["query", str(tmp_path / "ds"), "SELECT source, count(*) FROM battery GROUP BY source"]) == 0
    assert "bus.log.xz" in capsys.readouterr().out


def test_an_endless_line_in_an_xz_capture_is_refused(tmp_path: Path) -> None:
    endless = _endless_xz(tmp_path / "endless.log.xz", 64)
    assert endless.stat().st_size < 100_000
    with pytest.raises(InputError, match=f"a line of more than {MAX_LINE} bytes") as err:
        list(read_capture(endless, "endless.log.xz"))
    assert err.value.line == 1


def test_an_xz_capture_asking_for_a_huge_dictionary_is_refused_before_it_is_allocated(tmp_path: Path) -> None:
    liar = tmp_path / "liar.blf.xz"
    liar.write_bytes(_xz_asking_for(40, _blf([])))
    with pytest.raises(InputError, match=f"an xz stream needing more than {MAX_XZ_MEMORY} bytes"):
        list(read_capture(liar, "liar.blf.xz"))


@pytest.mark.parametrize("name", ["damaged.log.xz", "damaged.blf.xz", "cut.asc.xz"])
def test_a_damaged_xz_capture_is_one_located_error(tmp_path: Path, name: str) -> None:
    packed = bytearray(lzma.compress(b"(1436992770.657995) can0 1E3081FD#230D007B0100009B\n" * 200))
    if name.startswith("cut"):
        del packed[len(packed) // 2 :]
    else:
        packed[len(packed) // 2] ^= 0xFF
    path = tmp_path / name
    path.write_bytes(bytes(packed))
    with pytest.raises(InputError, match=r"damaged compressed capture|cannot"):
        list(read_capture(path, name))
    outcome = run_battgen("can", str(path), seconds=120)
    assert outcome.code in (1, 2) and "Traceback" not in outcome.stderr, outcome.stderr[-2000:]
    assert len(outcome.stderr.strip().splitlines()) == 1, outcome.stderr


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
    endless_xz = _endless_xz(tmp_path / "endless.log.xz", 256)
    liar_xz = tmp_path / "liar.log.xz"
    liar_xz.write_bytes(_xz_asking_for(40, b"(1.0) can0 123#00\n"))
    for path in (bomb, endless, endless_xz, liar_xz):
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


@pytest.mark.parametrize("start", ["4495139", "44528595139"])
def test_a_trc_start_time_beyond_any_date_is_one_located_error(tmp_path: Path, start: str) -> None:
    """python-can's TRC reader turns ``$STARTTIME`` (days since 1899-12-30) into a date: one beyond year 9999,
    or beyond a C int, raised OverflowError out of the reader (found by the long fuzz run on mutated TRC files;
    rebuilt here from the format)."""
    capture = tmp_path / "far.trc"
    capture.write_text(
        f";$FILEVERSION=1.1\n;$STARTTIME={start}\n      1)         1.0  Rx         0100  8  00 00 00 00 00 00 00 00\n",
        encoding="ascii",
    )
    with pytest.raises(InputError, match="cannot read the CAN capture"):
        list(read_capture(capture, "far.trc"))
    outcome = run_battgen("can", str(capture), seconds=120)
    assert outcome.code in (1, 2) and "Traceback" not in outcome.stderr, outcome.stderr[-2000:]


@pytest.mark.parametrize("method", [0, 2])
def test_an_object_of_size_0_inside_a_blf_container_is_refused_not_read_forever(tmp_path: Path, method: int) -> None:
    """python-can moves on by an inner object's stated size: 0 kept it on the same object forever (found by the
    long fuzz run on mutated BLF files; rebuilt here from the format)."""
    inner = struct.pack("<4sHHLL", b"LOBJ", 16, 3, 0, 86) + bytes(16)
    payload = inner if method == 0 else zlib.compress(inner)
    stuck = tmp_path / "stuck.blf"
    stuck.write_bytes(_blf([_container(payload, len(inner), method=method)]))
    with pytest.raises(InputError, match="an object inside it states a size of 0 bytes"):
        list(read_capture(stuck, "stuck.blf"))

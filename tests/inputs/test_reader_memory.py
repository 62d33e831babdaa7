"""Every reader under an address-space cap (``RLIMIT_AS``) on inflation bombs, endless lines and sizes that lie.

Each case reads one hostile file in a child process of its own whose address space is capped, so a reader that
allocates what the file asks for fails with MemoryError there (exit 3), not the machine. The cap is the child's
address space after it imported everything a reader uses, plus :data:`HEADROOM`: numpy (OpenBLAS) and pyarrow
(its allocator) reserve some 300 MB of address space at import that they never touch, and how much depends on
the machine (cores, allocator), so a fixed 300 MB cap would fail at ``import numpy``; measuring the base in the
child itself and adding 300 MB bounds exactly what the reading allocates. A reader that memory-maps the
file (the ULog and tlog readers while the file is held with a lease, pymavlink's DataFlash reader) gets the
file's size on top: a map is address space but not memory (the file's own pages, shared with the page cache and
dropped under pressure), and is what keeps a 2 GB ULog near 280 MB resident.

The files are made here, small on disk: compressed bombs, and "endless" lines written as sparse files (a text
prefix, then half a gigabyte of NUL bytes that take no disk). Each reader must read the file or refuse it with a
located error; both readings are tried where they differ: the data layer every log command reads through
(``read_view``: export, report, query) and the validator's records (``battgen validate``).
"""

from __future__ import annotations

import gzip
import json
import lzma
import struct
import subprocess
import sys
import zlib
from collections.abc import Callable
from pathlib import Path

import pytest

from codegen.cli.main import main
from codegen.errors import LocatedError
from codegen.inputs.devicetree.reading import read_nodes
from codegen.inputs.parameters.files import load
from codegen.text.files import MAX_WHOLE_FILE
from tests.shared_data import require, shared

HEADROOM = 300 << 20  # what a reader may allocate beyond the imports' address space
ENDLESS = 512 << 20  # an endless line: more than the headroom, so a reader that holds it fails
# pymavlink's DataFlash reader walks garbage a byte at a time in Python (minutes for 512 MB): its files stay small;
# it maps the file, so what it allocates is checked all the same
DATAFLASH_GARBAGE = 4 << 20
SEEDS = Path(__file__).resolve().parents[1] / "fuzz" / "seeds"

# The child: imports what any reader uses, measures its address space (VmSize), caps it at that plus the
# headroom, reads the file, and says how it ended: "read N", "refused: ..." (a located error), or exit 3 on
# MemoryError. Its peak resident size (VmHWM) is printed last.
_CHILD = """
import io, logging, resource, sys, contextlib
from pathlib import Path
logging.disable(logging.WARNING)
import numpy, pyarrow, can, can.io.blf, pymavlink.mavutil, pymavlink.DFReader
from codegen.apps.battery.view import read_view
from codegen.cli.main import main
from codegen.errors import BattgenError

def status(key):
    with open("/proc/self/status") as f:
        return int(next(line.split()[1] for line in f if line.startswith(key))) * 1024

headroom, mode, path, *rest = sys.argv[1:]
base = status("VmSize:") + (Path(path).stat().st_size if mode.endswith("-mapped") else 0)
mode = mode.removesuffix("-mapped")
resource.setrlimit(resource.RLIMIT_AS, (base + int(headroom), base + int(headroom)))
try:
    if mode == "view":
        n = sum(chunk.n for chunk in read_view(Path(path), message=rest[0] if rest else None))
        print("read", n)
    else:
        out = io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
            code = main(["validate", *rest, path])
        print("exit", code, out.getvalue()[-300:].replace("\\n", " | "))
except BattgenError as exc:
    print("refused:", str(exc)[:300])
except MemoryError:
    print("MemoryError")
    sys.exit(3)
print("peak", status("VmHWM:") >> 20, "base", base >> 20)
"""


def _sparse(path: Path, prefix: bytes, size: int = ENDLESS) -> Path:
    """``prefix``, then NUL bytes up to ``size`` without a newline: a line with no end, no disk spent on it."""
    with path.open("wb") as f:
        f.write(prefix)
        f.truncate(size)
    return path


def _endless_gzip(path: Path, mib: int = ENDLESS >> 20) -> Path:
    with gzip.open(path, "wb", compresslevel=1) as f:
        block = b"A" * (1 << 20)
        for _ in range(mib):
            f.write(block)
    return path


def _endless_xz(path: Path, mib: int = ENDLESS >> 20) -> Path:
    packer = lzma.LZMACompressor(preset=0)
    with path.open("wb") as f:
        block = b"A" * (1 << 20)
        for _ in range(mib):
            f.write(packer.compress(block))
        f.write(packer.flush())
    return path


def _blf_bomb(path: Path) -> Path:
    """A BLF whose one container inflates to 1 GiB of zeros (about 1 MB on disk)."""
    packer = zlib.compressobj(9)
    block = bytes(1 << 20)
    deflated = b"".join(packer.compress(block) for _ in range(1024)) + packer.flush()
    body = struct.pack("<H6xL4x", 2, 1 << 30) + deflated
    size = 16 + len(body)
    container = struct.pack("<4sHHLL", b"LOBJ", 16, 1, size, 10) + body + bytes(size % 4)
    header = struct.pack("<4sLBBBBBBBBQQLL8H8H", b"LOGG", 144, *([0] * 8), 0, 0, 1, 0, *([0] * 16))
    path.write_bytes(header + bytes(144 - len(header)) + container)
    return path


def _ulog_endless(path: Path) -> Path:
    """A real ULog's header and definitions, then half a gigabyte of zeros (messages of size 0 and type 0)."""
    return _sparse(path, (SEEDS / "flight.ulg").read_bytes()[:4096])


def _dataflash_endless(path: Path) -> Path:
    """A text DataFlash log: a FMT line, then a line with no end (its first 8 KiB digits, so the head that tells
    the kind is text)."""
    return _sparse(
        path, b"FMT, 128, 89, FMT, BBnNZ, Type,Length,Name,Format,Columns\nBAT, " + b"1" * 8192, DATAFLASH_GARBAGE
    )


def _dataflash_binary(path: Path) -> Path:
    """A real binary DataFlash log's start, then zeros (no message header anywhere in them)."""
    seed = require(shared("corpus", "realworld3b", "dataflash", "amc_backend_log_80k.bin")).read_bytes()
    return _sparse(path, seed[:8192], DATAFLASH_GARBAGE)


# readers that map the file (ULog; tlog; pymavlink's DataFlash reader): the cap counts its size (see above)
MAPPED = {"ulog-endless", "tlog-endless", "dataflash-binary-endless", "dataflash-text-endless"}
# name -> (file name, maker, read_view's message or None, validate's arguments); None: not a reading of that mode
CASES: dict[str, tuple[str, Callable[[Path], Path], tuple[str, ...] | None, tuple[str, ...] | None]] = {
    "ulog-endless": ("big.ulg", _ulog_endless, (), ("--message", "uorb.BatteryStatus")),
    "dataflash-text-endless": ("text.log", _dataflash_endless, (), None),
    "dataflash-binary-endless": ("zeros.bin", _dataflash_binary, (), None),
    "tlog-endless": ("zeros.tlog", lambda p: _sparse(p, (SEEDS / "flight.tlog").read_bytes()[:4096]), (), ()),
    "jsonl-endless": (
        "line.jsonl",
        lambda p: _sparse(p, json.dumps({"timestamp": 1, "voltage_v": 16.0}).encode() + b'\n{"voltage_v": 1'),
        ("uorb.BatteryStatus",),
        ("--message", "uorb.BatteryStatus"),
    ),
    "candump-endless": ("line.log", lambda p: _sparse(p, b"(1436992770.657995) can0 1E3081FD#23"), (), ()),
    "asc-endless": ("line.asc", lambda p: _sparse(p, b"date Sam Sep 30 15:06:13.191 2017\nbase hex\n"), (), ()),
    "trc-endless": ("line.trc", lambda p: _sparse(p, b";$FILEVERSION=2.1\n;$STARTTIME=43008.9\n"), (), ()),
    "candump-gz-bomb": ("bomb.log.gz", _endless_gzip, (), ()),
    "candump-xz-bomb": ("bomb.log.xz", _endless_xz, (), ()),
    "blf-bomb": ("bomb.blf", _blf_bomb, (), ()),
    "param-endless": ("line.param", lambda p: _sparse(p, b"BATT_MONITOR,4\nBATT_CAPACITY,"), None, ()),
    "dts-endless": ("line.dts", lambda p: _sparse(p, b'/dts-v1/;\n/ { battery { compatible = "'), None, ()),
}


def _run(mode: str, path: Path, args: tuple[str, ...]) -> subprocess.CompletedProcess[str]:
    command = [sys.executable, "-c", _CHILD, str(HEADROOM), mode, str(path), *args]
    return subprocess.run(command, capture_output=True, text=True, timeout=600, cwd=Path(__file__).parents[2])


@pytest.mark.parametrize("case", sorted(CASES))
def test_every_reader_stays_within_its_address_space_cap(tmp_path: Path, case: str) -> None:
    name, make, view_args, validate_args = CASES[case]
    path = make(tmp_path / name)
    for mode, args in (("view", view_args), ("validate", validate_args)):
        if args is None:
            continue
        done = _run(mode + ("-mapped" if case in MAPPED else ""), path, args)
        assert done.returncode == 0, (
            f"{case} ({mode}): exit {done.returncode}: {done.stdout[-500:]} {done.stderr[-2000:]}"
        )
        assert "Traceback" not in done.stderr, done.stderr[-2000:]
        first, *_, last = done.stdout.strip().splitlines()
        assert first.startswith(("read", "refused:", "exit 0", "exit 1", "exit 2")), (case, mode, first)
        assert last.startswith("peak"), (case, mode, done.stdout[-500:])
        print(case, mode, first[-250:], last)


@pytest.mark.parametrize(
    ("name", "prefix", "what"),
    [
        ("big.param", b"BATT_MONITOR,4\n", "a parameter file"),
        ("big.params", b"# Onboard parameters\n", "a parameter file"),
        ("big.dts", b"/dts-v1/;\n/ { };\n", "a devicetree source"),
        ("big.dtb", b"\xd0\x0d\xfe\xed", "a devicetree blob"),
    ],
)
def test_a_whole_file_input_larger_than_any_real_one_is_refused_unread(
    tmp_path: Path, name: str, prefix: bytes, what: str
) -> None:
    """Parameter files and devicetrees are read whole; one beyond MAX_WHOLE_FILE is one line, not a MemoryError
    hidden behind validate's catch-all ("cannot read: MemoryError()", found by the capped reads above)."""
    path = _sparse(tmp_path / name, prefix, MAX_WHOLE_FILE + 1)
    message = "devicetree.power.supply.battery" if "dt" in name else "params.BATT"
    code = main(["validate", "--message", message, str(path)])
    assert code == 2
    assert main(["validate", "--format", "json", "--message", message, str(path)]) == 2
    # the error as the readers raise it: located at the file, saying what was expected
    with pytest.raises(LocatedError, match=f"expected {what} of at most {MAX_WHOLE_FILE} bytes"):
        if "dt" in name:
            read_nodes(path)
        else:
            load(path)

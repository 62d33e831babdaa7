"""The data-side fuzz targets: each takes the bytes of one input and fails only on a defect.

A target runs one entry point on the bytes -- a generated decoder, a data reader with the validator
behind it, or a whole ``battgen`` command in-process -- and checks the promises of issue 10: no
exception but the documented ones (a decoder's ``DecodeError``, a reader's located error), every
message short and naming the file, exit status 0, 1 or 2 and never a traceback, and no defect masked by
a catch-all ("cannot read: ValueError(...)", "the validator failed"). The fuzzers (``test_fuzz_*.py``)
draw inputs for these targets; ``test_fuzz_crashers.py`` replays the saved inputs of
``crashers/<target>/`` through the same functions, so a crasher stays a regression test.
"""

from __future__ import annotations

import contextlib
import functools
import importlib
import io
import pkgutil
import re
import tempfile
from collections.abc import Callable, Collection, Iterator
from pathlib import Path
from typing import Any
from unittest import mock

import codegen.apps.gate.validate as validate_app
from codegen.apps.gate.validate import Checker, make_checker
from codegen.cli.main import main
from codegen.errors import BattgenError, LocatedError
from codegen.frontends.loader import load
from codegen.inputs.dispatch import read_records
from codegen.inputs.records import Notice, Record, Unreadable
from codegen.ir import Message, Schema
from generated import _mavlink
from generated.mavlink import BatteryStatus as MavBatteryStatus
from generated.uorb import BatteryStatus, BatteryStatusV0

ROOT = Path(__file__).resolve().parents[2]
SCHEMAS = ROOT / "schemas"
SEEDS = Path(__file__).resolve().parent / "seeds"
MAX_MESSAGE = 4000  # no message about hostile input may be longer than this (they quote values briefly)
# what a catch-all prints when a reader, from_dict or a validator raised something it should not have
MASKED = re.compile(r"cannot read: [A-Za-z]*(Error|Exception)\(|the validator failed|cannot read the record")

# -- decoders -----------------------------------------------------------------------------------------------


def _classes(package: str) -> tuple[Any, ...]:
    """Every generated message class under a package of ``generated`` (unions and nested types too)."""
    root = importlib.import_module(package)
    found: dict[str, Any] = {}
    for info in pkgutil.walk_packages(root.__path__, package + "."):
        module = importlib.import_module(info.name)
        for value in vars(module).values():
            if isinstance(value, type) and hasattr(value, "QUALIFIED_NAME") and hasattr(value, "decode"):
                found[value.QUALIFIED_NAME] = value
    return tuple(found[name] for name in sorted(found))


DRONECAN = _classes("generated.dronecan")
UORB = (BatteryStatus, BatteryStatusV0)


def _round_trip(obj: Any, encode: Callable[[Any], bytes], decode: Callable[[bytes], Any]) -> None:
    """What a decoder produced, the encoder takes, and decoding that gives the same values back."""
    again = decode(encode(obj))
    assert again == obj, (obj, again)


@functools.cache
def _pydronecan_type(qualified: str) -> Any:
    """pydronecan's type of the same DSDL name (None where the ``dronecan`` package has none)."""
    try:
        import dronecan
    except ImportError:
        return None
    return dronecan.TYPENAMES.get(qualified.removeprefix("dronecan."))


def _as_pydronecan_re_encodes(cls: Any, data: bytes, tao: bool, obj: Any) -> None:
    """pydronecan reads what we decoded and writes it back; decoding that gives our values again (NaN
    payloads aside: pydronecan keeps the bits it read, so bytes are compared through our decoder)."""
    ref_type = _pydronecan_type(cls.QUALIFIED_NAME)
    if ref_type is None:
        return
    from dronecan import transport

    ref = transport.CompoundValue(ref_type, _mode=None)
    ref._unpack(transport.bits_from_bytes(data), tao)
    again = bytes(transport.bytes_from_bits(ref._pack(tao)))
    assert cls.decode(again, tao=tao) == obj, (cls.QUALIFIED_NAME, tao, data.hex(), again.hex())


def decode_dronecan(data: bytes) -> None:
    for cls in DRONECAN:
        for tao in (True, False):
            try:
                obj = cls.decode(data, tao=tao)
            except ValueError:  # DecodeError
                continue
            _round_trip(obj, lambda o, t=tao: o.encode(tao=t), lambda b, c=cls, t=tao: c.decode(b, tao=t))
            _as_pydronecan_re_encodes(cls, data, tao, obj)


def decode_uorb(data: bytes) -> None:
    for cls in UORB:
        for size in (len(data), 168, 166, 64):  # the bytes as given, and cut or zero-filled to a struct size
            chunk = data[:size].ljust(size, b"\0")
            try:
                obj = cls.decode(chunk)
            except ValueError:
                continue
            _round_trip(obj, lambda o: o.encode(), cls.decode)


def decode_mavlink(data: bytes) -> None:
    try:
        obj = MavBatteryStatus.decode(data)
    except ValueError:
        pass
    else:
        _round_trip(obj, lambda o: o.encode(), MavBatteryStatus.decode)
        _round_trip(obj, lambda o: o.encode_frame(seq=1, sysid=2, compid=3), MavBatteryStatus.decode_frame)
    for call in (MavBatteryStatus.decode_frame, _mavlink.decode_message, _mavlink.parse_frame):
        try:
            call(data)
        except ValueError:  # FrameError, DecodeError
            pass
    # a stream fed in two pieces finds what it finds in one, and each counter stays consistent
    whole, split = _mavlink.StreamParser(), _mavlink.StreamParser()
    cut = len(data) // 3
    frames = whole.feed(data)
    assert [f.payload for f in frames] == [f.payload for f in split.feed(data[:cut]) + split.feed(data[cut:])]
    assert whole.frames == len(frames) == split.frames and whole.pending == split.pending
    # strict: the same frames, each rejection raised once after consuming it (so feeding on ends)
    strict = _mavlink.StreamParser(strict=True)
    found: list[bytes] = []
    piece = data
    for _ in range(len(data) + 2):
        try:
            found += [f.payload for f in strict.feed(piece)]
        except _mavlink.FrameError:
            piece = b""
            continue
        break
    else:
        raise AssertionError("the strict parser raised more errors than there are bytes")
    assert found == [f.payload for f in frames] and strict.frames == whole.frames


# -- readers ------------------------------------------------------------------------------------------------


@functools.cache
def _schema() -> Any:
    return load([SCHEMAS])


@functools.cache
def checker(message: str) -> tuple[Message, Checker]:
    with _cached_schemas():
        return make_checker(SCHEMAS, message)


@contextlib.contextmanager
def _cached_schemas() -> Iterator[None]:
    """The bundled schemas loaded once for all examples (the commands load them on every run)."""

    def cached(schema_dir: Path, *, only: Collection[str] | None = None) -> Schema:
        # the whole folder serves any ``only``
        return _schema() if schema_dir == SCHEMAS else load([schema_dir], only=only)

    with mock.patch.object(validate_app, "load_schemas", cached):
        yield


SUFFIX = {
    "json": ".json",
    "jsonl": ".jsonl",
    "yaml": ".yaml",
    "dts": ".dts",
    "dtb": ".dtb",
    "param": ".param",
    "params": ".params",
    "ulog": ".ulg",
    "tlog": ".tlog",
    "mavlink": ".mav",
}
KIND = {name: ("param" if name == "params" else name) for name in SUFFIX}
MESSAGES = {
    "json": ("uorb.BatteryStatus", "devicetree.power.supply.battery", "dronecan.uavcan.equipment.power.BatteryInfo"),
    "jsonl": ("uorb.BatteryStatus", "mavlink.BATTERY_STATUS"),
    "yaml": ("uorb.BatteryStatus", "devicetree.power.supply.battery"),
    "dts": ("devicetree.power.supply.battery",),
    "dtb": ("devicetree.power.supply.battery",),
    "param": ("params.BATT",),
    "params": ("params.BATT",),
    "ulog": ("uorb.BatteryStatus",),
    "tlog": ("mavlink.BATTERY_STATUS",),
    "mavlink": ("mavlink.BATTERY_STATUS",),
}


@contextlib.contextmanager
def input_file(name: str, data: bytes) -> Iterator[Path]:
    with tempfile.TemporaryDirectory(prefix="battgen-fuzz-") as folder:
        path = Path(folder) / f"input{SUFFIX[name]}"
        path.write_bytes(data)
        yield path


def _short(text: str, what: str) -> None:
    assert len(text) <= MAX_MESSAGE, f"{what} of {len(text)} characters: {text[:300]}..."
    assert not MASKED.search(text), f"a defect hidden by a catch-all: {text[:500]}"


def read(name: str, data: bytes) -> None:
    """Every item of the file for each message it may hold, each record through the validator."""
    with input_file(name, data) as path:
        for message_name in MESSAGES[name]:
            message, check = checker(message_name)
            try:
                for item in read_records(path, message, model=check.cls, kind=KIND[name]):
                    if isinstance(item, Record):
                        for finding in check.check(item):
                            _short(finding.message, "a finding")
                    elif isinstance(item, Unreadable | Notice):
                        _short(item.message, "a notice")
            except LocatedError as exc:
                _short(str(exc), "an error")
                assert exc.file, f"an error that names no file: {exc}"
            except BattgenError as exc:
                _short(str(exc), "an error")


# -- the commands -------------------------------------------------------------------------------------------


def _commands(name: str, path: str) -> list[list[str]]:
    p = path
    if name in ("param", "params"):
        return [["validate", p], ["params", "--check", p], ["validate", "--format", "json", p]]
    if name in ("dts", "dtb"):
        return [["validate", "--message", "simple-battery", p], ["params", "--from-devicetree", p],
                ["convert", "--from", "devicetree", "--to", "uorb", p]]  # fmt: skip
    fleet = ["export", "-q", "-o", str(Path(p).parent / "fleet"), p]  # the export's own readers (the C walk)
    if name in ("tlog", "mavlink"):
        return [
            ["validate", "--message", "mavlink.BATTERY_STATUS", p],
            ["convert", "--from", "mavlink", "--to", "uorb", p],
            *([fleet] if name == "tlog" else []),
        ]
    if name == "ulog":
        return [
            ["validate", "--message", "uorb.BatteryStatus", p],
            ["convert", "--from", "uorb", "--to", "mavlink", p],
            fleet,
        ]
    return [
        ["validate", "--message", "uorb.BatteryStatus", p],
        ["validate", "--format", "json", "--message", "devicetree.power.supply.battery", p],
        ["convert", "--from", "uorb", "--to", "dronecan", "--report", p],
        ["failsafe", "--params", str(SEEDS / "vehicle.param"), p],
    ]


def run_main(argv: list[str]) -> tuple[int, str, str]:
    """``battgen argv`` in this process: (exit status, stdout, stderr); an exception escaping main() is a
    traceback the user would have seen, so it propagates and fails the fuzzer."""
    out = io.TextIOWrapper(io.BytesIO(), encoding="utf-8", errors="replace")
    err = io.TextIOWrapper(io.BytesIO(), encoding="utf-8", errors="replace")
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), _cached_schemas():
        try:
            code = main(argv)
        except SystemExit as exc:  # argparse
            code = exc.code if isinstance(exc.code, int) else 2
        finally:
            out.flush()
            err.flush()
    texts = [s.buffer.getvalue().decode("utf-8", "replace") for s in (out, err)]  # type: ignore[attr-defined]
    return code, texts[0], texts[1]


def command(name: str, data: bytes) -> None:
    """Each command a user would run on such a file ends with 0, 1 or 2 and short, located messages."""
    with input_file(name, data) as path:
        for argv in _commands(name, str(path)):
            code, stdout, stderr = run_main(argv)
            assert code in (0, 1, 2), (argv, code, stderr[-2000:])
            assert "Traceback" not in stderr
            assert not MASKED.search(stdout + stderr), (argv, stderr[-2000:])
            for line in stderr.splitlines():
                assert len(line) <= MAX_MESSAGE, (argv, line[:300])
            if code == 2:
                assert (stderr + stdout).strip(), (argv, "exit 2 without a word")


TARGETS: dict[str, Callable[[bytes], None]] = {
    "decode-dronecan": decode_dronecan,
    "decode-uorb": decode_uorb,
    "decode-mavlink": decode_mavlink,
    **{f"read-{name}": functools.partial(read, name) for name in SUFFIX},
    **{f"cli-{name}": functools.partial(command, name) for name in SUFFIX},
}


def seeds(name: str) -> list[bytes]:
    """Valid inputs of a kind, for the fuzzers to mutate: the seed corpus and the repository's test data."""
    data = ROOT / "tests" / "data"
    files = {
        "json": [data / "instances" / "uorb_valid.json", data / "instances" / "uorb_invalid.json"],
        "jsonl": [data / "instances" / "uorb_records.jsonl"],
        "yaml": [data / "instances" / "uorb_stream.yaml"],
        "dts": [data / "instances" / "battery_board.dts", data / "devicetree" / "valid_minimal.dts"],
        "dtb": [SEEDS / "board.dtb"],
        "param": [SEEDS / "vehicle.param"],
        "params": [SEEDS / "vehicle.params"],
        "ulog": [SEEDS / "flight.ulg"],
        "tlog": [SEEDS / "flight.tlog"],
        "mavlink": [SEEDS / "capture.mav"],
    }[name]
    return [f.read_bytes() for f in files]

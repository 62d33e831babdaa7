"""Fuzzing the data layer every log command reads through (``read_view``: ULog, DataFlash, tlog, CAN captures in
candump, ASC, BLF and TRC, also gzip- and xz-compressed, JSON Lines), on mutated real files of
``../shared/corpus`` and the seed corpus: a log either reads or raises a located BattgenError naming it, with a
short message -- never another exception, a hang or a memory blow-up (the BLF, text and decompression bounds of
codegen/inputs/can/bounded.py included).

A failing input becomes a regression: rebuilt from the format as a test of its own where it is a mutation of an
upstream file (the corpus stays in ``../shared``), else saved under ``tests/fuzz/crashers/view-<kind>/`` and
replayed on every run here.
``BATTGEN_FUZZ=long`` runs far more inputs per kind (tests/fuzz/budget.py).
"""

from __future__ import annotations

import functools
import lzma
import tempfile
from pathlib import Path

import pytest
from budget import crashers, fuzz_settings
from dataflash_seeds import thinned
from fuzz_inputs import mutated
from hypothesis import given
from hypothesis import strategies as st

from codegen.apps.battery.catalog import bundled_catalog
from codegen.apps.battery.view import read_view
from codegen.errors import BattgenError
from tests.shared_data import require, shared

SEEDS = Path(__file__).resolve().parent / "seeds"
MAX_MESSAGE = 4000
# kind -> (suffix, seed files: the seed corpus, then small real files of the shared corpus)
KINDS: dict[str, tuple[str, list[Path]]] = {
    "ulog": (".ulg", [SEEDS / "flight.ulg"]),
    "tlog": (".tlog", [SEEDS / "flight.tlog", shared("corpus", "realworld3b", "tlog", "dronekit-python_test.tlog")]),
    # thinned (dataflash_seeds.py): every format, the first records of each type the layer reads
    "dataflash": (
        ".bin",
        [
            shared("corpus", "realworld3b", "dataflash", name)
            for name in ("amc_backend_log_80k.bin", "wlichon_00000001.BIN", "dronekit_log171.bin")
        ],
    ),
    "candump": (".log", [shared("corpus", "realworld3b", "can", "px4-issue2568_uavcan_v0.log")]),
    "asc": (".asc", [shared("corpus", "realworld3b", "can", "pythoncan_logfile.asc")]),
    "blf": (
        ".blf",
        [
            shared("corpus", "realworld3b", "can", "pythoncan_test_CanMessage.blf"),
            shared("corpus", "realworld3b", "can", "pythoncan_test_CanFdMessage.blf"),
        ],
    ),
    "trc": (
        ".trc",
        [
            shared("corpus", "realworld3b", "can", "pythoncan_test_CanMessage_V1_1.trc"),
            shared("corpus", "realworld3b", "can", "pythoncan_test_CanMessage_V2_1.trc"),
        ],
    ),
    # compressed streams, mutated as stored (damaged, cut, lying streams)...
    "asc-gz": (".asc.gz", [shared("corpus", "realworld3b", "can", "pythoncan_test_CanMessage.asc.gz")]),
    "candump-xz": (".log.xz", [shared("corpus", "realworld3b", "can", "px4-issue2568_uavcan_v0.log")]),
    # ... and captures mutated, then compressed (what the readers behind the inflation see)
    "blf-in-xz": (".blf.xz", [shared("corpus", "realworld3b", "can", "pythoncan_test_CanMessage.blf")]),
    "jsonl": (".jsonl", [Path(__file__).resolve().parents[1] / "data" / "instances" / "uorb_records.jsonl"]),
}
SEEDS_PACKED = {"candump-xz"}  # the seeds are xz-compressed, then mutated
INPUTS_PACKED = {"blf-in-xz"}  # the mutated bytes are xz-compressed before they are read


@functools.cache
def _seeds(kind: str) -> list[bytes]:
    if kind == "dataflash":
        return [thinned(require(p)) for p in KINDS[kind][1]]
    seeds = [require(p).read_bytes() for p in KINDS[kind][1]]
    return [lzma.compress(s, preset=1) for s in seeds] if kind in SEEDS_PACKED else seeds


def view(kind: str, data: bytes) -> None:
    """Every chunk of the bytes read as a log of ``kind``; a BattgenError is the one allowed failure."""
    suffix = KINDS[kind][0]
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"input{suffix}"
        path.write_bytes(lzma.compress(data, preset=0) if kind in INPUTS_PACKED else data)
        try:
            for chunk in read_view(
                path, path.name, catalog=bundled_catalog(), message="uorb.BatteryStatus" if kind == "jsonl" else None
            ):
                assert chunk.n >= 0
        except BattgenError as exc:
            text = str(exc)
            assert len(text) <= MAX_MESSAGE, text[:200]
            assert "input" in text or text.startswith("the generated"), text


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_fuzz_data_layer(kind: str) -> None:
    seeds = _seeds(kind)
    for saved in crashers(f"view-{kind}"):  # inputs that once failed here, first
        view(kind, saved.read_bytes())

    @fuzz_settings(ci=40)
    @given(st.one_of(mutated(seeds), st.binary(max_size=512)))
    def run(data: bytes) -> None:
        view(kind, data)

    run()

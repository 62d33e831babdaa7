"""DataFlash battery reading: battgen's batches against pymavlink's DFReader on the same log.

* pymavlink: ``DFReader_binary`` (or ``DFReader_text``), ``recv_match`` over the battery types
  (``BAT``, ``CURR`` ...) and ``to_dict`` per record -- what a user writes by hand;
* battgen: :func:`codegen.apps.battery.dataflash_batches.dataflash_batches` (the same walk, plus
  units, clock, arming, GPS time and the concepts).

Prints battery records per second for both and the ratio (battgen / pymavlink), one run each.

Usage: python benchmarks/bench_dataflash.py [LOG]   (default: the largest DataFlash log of ../shared/corpus)
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from codegen.apps.battery.catalog import bundled_catalog
from codegen.apps.battery.dataflash_batches import dataflash_batches
from codegen.inputs.dataflash.log import BATTERY_TYPES

CORPUS = Path(__file__).resolve().parents[1].parent / "shared" / "corpus"


def default_log() -> Path:
    logs = [p for p in CORPUS.rglob("*") if p.suffix.lower() == ".bin" and p.is_file()]
    if not logs:
        raise SystemExit(f"no DataFlash log under {CORPUS}; give one")
    return max(logs, key=lambda p: p.stat().st_size)


def run(path: Path) -> dict[str, float]:
    from pymavlink import DFReader

    catalog = bundled_catalog()
    start = time.perf_counter()
    cls = DFReader.DFReader_binary if path.suffix.lower() == ".bin" else DFReader.DFReader_text
    reader = cls(str(path), zero_time_base=True)
    ref = 0
    while (msg := reader.recv_match(type=sorted(BATTERY_TYPES))) is not None:
        msg.to_dict()
        ref += 1
    ref_s = time.perf_counter() - start
    start = time.perf_counter()
    ours = sum(b.n for b in dataflash_batches(path, path.name, catalog))
    ours_s = time.perf_counter() - start
    figures = {"records": float(ours), "ref_records": float(ref), "ours_rps": ours / ours_s, "ref_rps": ref / ref_s}
    print(
        f"{path.name}: {ours} battery records; battgen {figures['ours_rps']:,.0f} records/s, "
        f"pymavlink DFReader {figures['ref_rps']:,.0f} records/s, ratio {figures['ours_rps'] / figures['ref_rps']:.2f}x"
    )
    return figures


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("log", nargs="?", type=Path)
    parser.add_argument("--quick", action="store_true", help="tiny sizes, one round (a smoke run)")
    args = parser.parse_args(argv)
    return run(args.log or default_log())


if __name__ == "__main__":
    main()

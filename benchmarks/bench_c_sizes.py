"""Code and data size of the generated C library on a Cortex-M4, per message.

Run: python benchmarks/bench_c_sizes.py
Builds generated/c's sources with Debian's arm-none-eabi-gcc (-Os -mthumb -mcpu=cortex-m4, the strict
warnings) into a temp dir and prints, per message, the bytes of its functions (codecs and validator,
the check functions its validator calls included) and of its data; the shared inline helpers count
where the compiler placed them.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
GENERATED = ROOT / "generated" / "c"
FLAGS = ["-std=c99", "-Wall", "-Wextra", "-Wconversion", "-Werror", "-pedantic", "-ffreestanding"]
TARGET = ["-Os", "-mthumb", "-mcpu=cortex-m4"]


def owner(symbol: str, messages: list[str]) -> str:
    """The message a symbol belongs to (the longest type name it holds), else the shared helpers."""
    found = [m for m in messages if m in symbol]
    return max(found, key=len) if found else "(shared)"


def measure() -> dict[str, dict[str, int]]:
    """Message type name (or ``(shared)``) -> its ``code`` and ``data`` bytes on a Cortex-M4."""
    sizes: dict[str, dict[str, int]] = defaultdict(lambda: {"code": 0, "data": 0})
    with tempfile.TemporaryDirectory() as tmp:
        for src in sorted(GENERATED.glob("*.c")):
            obj = Path(tmp) / (src.name + ".o")
            cc = ["arm-none-eabi-gcc", *FLAGS, *TARGET, "-ffunction-sections", "-fdata-sections"]
            subprocess.run([*cc, "-I", str(GENERATED), "-c", str(src), "-o", str(obj)], check=True, timeout=300)
            headers = sorted(GENERATED.glob(f"{src.stem}/**/*.h"))
            messages = ["battgen_" + "_".join(h.relative_to(GENERATED).with_suffix("").parts) for h in headers]
            nm = subprocess.run(
                ["arm-none-eabi-nm", "-S", "--size-sort", str(obj)], capture_output=True, text=True, check=True
            )
            for line in nm.stdout.splitlines():
                _, size, kind, name = line.split()
                key = "code" if kind.lower() == "t" else "data"
                sizes[owner(name, messages)][key] += int(size, 16)
    return dict(sizes)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="tiny sizes, one round (a smoke run)")
    parser.parse_args(argv)  # --quick: the sizes take one build either way
    if shutil.which("arm-none-eabi-gcc") is None or shutil.which("arm-none-eabi-nm") is None:
        print("arm-none-eabi-gcc not installed (Debian: gcc-arm-none-eabi)")
        return 1
    sizes = measure()
    width = max(len(k) for k in sizes)
    print(f"{'message':<{width}}  {'code B':>7}  {'data B':>7}")
    for name in sorted(sizes):
        print(f"{name.removeprefix('battgen_'):<{width}}  {sizes[name]['code']:>7}  {sizes[name]['data']:>7}")
    total_code = sum(v["code"] for v in sizes.values())
    total_data = sum(v["data"] for v in sizes.values())
    print(f"{'total':<{width}}  {total_code:>7}  {total_data:>7}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

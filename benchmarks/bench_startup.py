"""Start-up: what every command pays before it reads a log, with the bundled schemas' catalog.

Each figure is one run of a fresh interpreter (a subprocess), as a user's command is:

* ``bundled_catalog()``: battgen's path (the bundled mapping files take the compiled check of their
  JSON Schema, only the formats the mappings name are read) against the jsonschema path it replaced
  (every schema folder read, each mapping file checked by a jsonschema validator built for it);
* ``battgen --help`` and ``battgen export LOG -o DIR`` as a user runs them, battgen's path against
  the same command with the jsonschema path put back before the CLI is imported.

Prints the seconds of each and the ratios (jsonschema path / ours).

Usage: python benchmarks/bench_startup.py [LOG]   (default: ../shared/data/ulog/sample_px4_events.ulg)
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_LOG = ROOT.parent / "shared" / "data" / "ulog" / "sample_px4_events.ulg"

# puts back the start-up this benchmark compares with: a jsonschema validator built per mapping file,
# every mapping file checked by jsonschema, every folder of the bundled schemas read
_JSONSCHEMA_PATH = """
import functools
from pathlib import Path
import codegen.frontends.mappings as m
m._BUNDLED_DIR = Path("/nonexistent")
m._validator = m._validator.__wrapped__
import codegen.apps.battery.catalog as c
c.bundled_catalog = functools.cache(lambda d=None: c.build_catalog(c.load([d or c.bundled_schemas()])))
"""

_CATALOG = """
import time
from codegen.apps.battery.catalog import bundled_catalog
start = time.perf_counter()
bundled_catalog()
print(time.perf_counter() - start)
"""

_CLI = """
import sys
from codegen.cli.main import main
sys.exit(main(sys.argv[1:]))
"""


def _python(code: str, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, check=True, cwd=ROOT)


def _wall(code: str, *args: str) -> float:
    start = time.perf_counter()
    _python(code, *args)
    return time.perf_counter() - start


def run(log: Path = DEFAULT_LOG) -> dict[str, float]:
    figures: dict[str, float] = {
        "catalog_ours_s": float(_python(_CATALOG).stdout),
        "catalog_jsonschema_s": float(_python(_JSONSCHEMA_PATH + _CATALOG).stdout),
        "help_ours_s": _wall(_CLI, "--help"),
        "help_jsonschema_s": _wall(_JSONSCHEMA_PATH + _CLI, "--help"),
    }
    with tempfile.TemporaryDirectory() as tmp:
        figures["export_ours_s"] = _wall(_CLI, "export", str(log), "-o", str(Path(tmp) / "ours"), "-q")
        figures["export_jsonschema_s"] = _wall(
            _JSONSCHEMA_PATH + _CLI, "export", str(log), "-o", str(Path(tmp) / "jsonschema"), "-q"
        )
    print(f"start-up, one fresh interpreter each (export of {log.name})")
    print(f"{'':24}{'ours':>9}{'jsonschema':>12}{'ratio':>8}")
    for name, label in (("catalog", "bundled_catalog()"), ("help", "battgen --help"), ("export", "battgen export")):
        ours, theirs = figures[f"{name}_ours_s"], figures[f"{name}_jsonschema_s"]
        print(f"{label:24}{ours:8.3f}s{theirs:11.3f}s{theirs / ours:7.2f}x")
    return figures


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("log", nargs="?", type=Path, default=DEFAULT_LOG)
    run(parser.parse_args().log)

"""The ArduCopter 3.3 log (pre-3.6 CURR in hundredths, no LOG_DISARMED, FS_BATT_* names) replayed
through the failsafe: volts and amps, the log's own older parameter names, t since the log's start."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from shared_data import SHARED

from codegen.apps.battery.catalog import bundled_catalog
from codegen.apps.battery.dataflash_batches import dataflash_batches
from codegen.apps.failsafe.legacy_parameters import with_current_names
from codegen.apps.failsafe.logs import log_samples, own_parameters
from codegen.cli.main import main
from codegen.inputs.dataflash.log import battery_records, open_log

LOG = SHARED / "corpus" / "realworld3" / "dataflash" / "dronekit_log171.bin"


@pytest.fixture
def log() -> Path:
    if not LOG.is_file():
        if os.environ.get("CI"):
            pytest.fail(f"missing {LOG}")
        pytest.skip(f"missing {LOG}")
    return LOG


def test_legacy_names_map_to_batt(log: Path) -> None:
    params = own_parameters(log_samples(log))
    assert params is not None
    assert params["BATT_LOW_VOLT"] == 14.0 and params["BATT_LOW_MAH"] == 520.0 and params["BATT_FS_LOW_ACT"] == 2.0
    assert with_current_names({"FS_BATT_VOLTAGE": 10.0, "BATT_LOW_VOLT": 11.0})["BATT_LOW_VOLT"] == 11.0


def test_own_parameters_do_not_fire(log: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # ArduPilot's rule with the log's settings: min 14.91 V stays above FS_BATT_VOLTAGE 14.0, and
    # 1196 mAh used leaves 4004 of BATT_CAPACITY 5200, above FS_BATT_MAH 520: no failsafe.
    rows = list(battery_records(open_log(log)))
    assert min(r.voltage_v or 99 for r in rows) == pytest.approx(14.91)
    assert max(r.consumed_mah or 0 for r in rows) == pytest.approx(1196.0)
    assert main(["failsafe", log.as_posix()]) == 0
    captured = capsys.readouterr()
    assert "2384 samples, 0 events" in captured.out + captured.err


def test_low_fires_where_the_rule_fires(log: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # BATT_LOW_VOLT 15.5: LOW once the voltage has stayed below it for more than BATT_LOW_TIMER (10 s)
    batch = dataflash_batches(log, log.name, bundled_catalog())[0]
    volts, t, armed = batch.columns["Volt"], batch.t, batch.armed
    assert armed is not None
    start = expected = None
    for ti, vi, ai in zip(t.tolist(), volts.tolist(), armed.tolist(), strict=True):
        if vi < 15.5 and ai == 1.0:
            start = ti if start is None else start
            if ti - start > 10.0:
                expected = ti
                break
        else:
            start = None
    assert expected is not None
    params = tmp_path / "low.param"
    params.write_text("BATT_LOW_VOLT 15.5\n")
    assert main(["failsafe", "--vehicle", "copter", "--params", params.as_posix(), log.as_posix()]) == 0
    captured = capsys.readouterr()
    out = captured.out + captured.err
    assert f"t={expected:10.3f}s  battery 1 LOW" in out


def test_clock_and_arming(log: Path) -> None:
    batch = dataflash_batches(log, log.name, bundled_catalog())[0]
    assert batch.origin_us == 11_459_000  # the first record's TimeMS, µs since boot
    assert batch.t[0] == pytest.approx(11.477 - 11.459)
    assert batch.armed is not None and batch.armed[0] == 0.0 and batch.armed[-1] == 1.0  # EV 10 at 72.6 s
    assert any("APM:Copter V3.3" in n for n in batch.notes)
    context = batch.context
    assert context is not None and context.firmware == "APM:Copter V3.3-dev (ae3192b8)"
    assert context.hardware == "PX4v2"  # "PX4v2 004A002F 33345119 32383433": the board and its unique id
    assert context.arming_rule and context.arming[0] == (0.0, False)


def _corpus_log(name: str) -> Path:
    path = SHARED / "corpus" / "realworld3b" / "dataflash" / name
    if not path.is_file():
        path = SHARED / "corpus" / "realworld3" / "dataflash" / name
    if not path.is_file():
        if os.environ.get("CI"):
            pytest.fail(f"missing {path}")
        pytest.skip(f"missing {path}")
    return path


def test_log_disarmed_0_armed_from_the_first_record() -> None:
    # LOG_DISARMED 0, one ARM record (ArmState 0 at the end): armed from the log's start until it
    path = _corpus_log("wlichon_00000001.BIN")
    batch = dataflash_batches(path, path.name, bundled_catalog())[0]
    assert batch.context is not None and batch.context.parameters["LOG_DISARMED"] == 0.0
    assert batch.armed is not None and batch.armed[0] == 1.0
    assert set(batch.armed.tolist()) <= {0.0, 1.0}


def test_log_disarmed_0_without_arm_records_is_armed_throughout() -> None:
    path = _corpus_log("methodic_backend_log_80k.bin")
    batch = dataflash_batches(path, path.name, bundled_catalog())[0]
    assert batch.armed is not None and batch.n > 0 and (batch.armed == 1.0).all()
    assert batch.t[0] >= 0.0 and batch.origin_us > 0


def test_failsafe_reads_the_log_once(
    log: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # the log's own parameters come with the battery view's read (its context), not from a second pass over PARM
    from codegen.apps.battery.view import read_view
    from codegen.inputs.dataflash import log as dataflash

    opened: list[Path] = []
    real = dataflash._open

    def counting(path: Path, *args: object, **kwargs: object) -> object:
        opened.append(path)
        return real(path, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(dataflash, "_open", counting)
    list(read_view(log))
    by_view = len(opened)
    opened.clear()
    assert main(["failsafe", log.as_posix()]) == 0
    capsys.readouterr()
    assert len(opened) == by_view + 1  # and one filtered pass over ERR, MSG and MODE: what the firmware logged

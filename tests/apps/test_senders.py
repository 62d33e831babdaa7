"""``battgen convert --sender nxp-bms772``: NXP's BMS temperatures read with its own constant, said in the loss report.

The fact pinned here: NXP's RDDRONE-BMS772 firmware (NXP rddrone-bms772 repository, ``src/uavcan.c``) defines
``CELSIUS_TO_KELVIN`` as 272.15 and sends ``temperature_min_max[i].kelvin`` as its degrees Celsius plus that
constant, so a reader using UDRAL's 273.15 gets every temperature 1 K low. The source cannot be fetched in a test:
the constant is stated here and in :mod:`codegen.apps.conversion.senders`, and the conversion is checked against it.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from codegen.apps.conversion import senders as senders
from codegen.cli.main import main

NXP_CELSIUS_TO_KELVIN = 272.15  # NXP rddrone-bms772, src/uavcan.c: #define CELSIUS_TO_KELVIN 272.15
CELSIUS = (21.5, 34.25)  # what the BMS measured: its coldest and hottest sensor


def _record(path: Path) -> Path:
    """A UDRAL record as NXP's firmware fills it: each temperature its degrees Celsius + 272.15."""
    sent = [{"kelvin": c + NXP_CELSIUS_TO_KELVIN} for c in CELSIUS]
    record = {
        "source": {"value": {"power": {"voltage": {"volt": 22.2}, "current": {"ampere": -3.0}}}},
        "status": {"temperature_min_max": sent},
    }
    path.write_text(json.dumps(record) + "\n")
    return path


def _convert(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, list[dict[str, object]], str]:
    code = main(["convert", "--from", "udral", "--to", "uorb", "--report", "--in-format", "jsonl", *args])
    out, err = capsys.readouterr()
    return code, [json.loads(x) for x in out.splitlines()], err


def test_the_constant_is_nxp_s() -> None:
    assert senders.NXP_CELSIUS_TO_KELVIN == NXP_CELSIUS_TO_KELVIN
    assert senders.KELVIN_AT_0_C - senders.NXP_CELSIUS_TO_KELVIN == pytest.approx(1.0)


def test_nxp_temperatures_are_read_with_272_15_and_said_so(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _record(tmp_path / "nxp.jsonl")
    code, (converted,), _ = _convert(capsys, "--sender", "nxp-bms772", str(path))
    assert code == 0
    record, loss = converted["record"], converted["loss"]
    assert isinstance(record, dict) and isinstance(loss, list)
    # the hottest sensor, in °C as the BMS measured it (uORB's float32)
    assert record["temperature"] == pytest.approx(max(CELSIUS), abs=1e-5)
    corrected = [e for e in loss if e["kind"] == "corrected"]
    assert [e["field"] for e in corrected] == [
        f"cyphal.reg.udral.service.battery.Status_0_2.temperature_min_max.{i}.kelvin" for i in range(2)
    ]
    assert all("272.15" in e["detail"] and "nxp-bms772" in e["detail"] for e in corrected)
    # as sent, read with UDRAL's 273.15: one kelvin low, and nothing corrected
    code, (plain,), _ = _convert(capsys, str(path))
    assert code == 0 and not [e for e in plain["loss"] if e["kind"] == "corrected"]  # type: ignore[union-attr]
    assert plain["record"]["temperature"] == pytest.approx(max(CELSIUS) - 1.0, abs=1e-4)  # type: ignore[index]


def test_an_unknown_temperature_stays_unknown(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "nan.jsonl"
    record = {
        "source": {"value": {"power": {"voltage": {"volt": 22.2}, "current": {"ampere": -3.0}}}},
        "status": {"temperature_min_max": [{"kelvin": "NaN"}, {"kelvin": "NaN"}]},
    }
    path.write_text(json.dumps(record) + "\n")
    code, (converted,), err = _convert(capsys, "--sender", "nxp-bms772", str(path))
    assert code == 0, err
    assert not [e for e in converted["loss"] if e["kind"] == "corrected"]  # type: ignore[union-attr]


@pytest.mark.parametrize(
    ("args", "said"),
    [
        (["--policy", "px4"], "give one of them"),  # PX4 does not correct what it receives: not both at once
        (["--from", "dronecan"], "its records are udral's, but this converts from dronecan"),
    ],
)
def test_a_sender_that_does_not_fit_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], args: list[str], said: str
) -> None:
    path = _record(tmp_path / "nxp.jsonl")
    code, _, err = _convert(capsys, "--sender", "nxp-bms772", *args, str(path))
    assert code == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1 and said in err

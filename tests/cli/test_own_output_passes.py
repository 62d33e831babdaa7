"""battgen's own converter output passes battgen's own validator under the target firmware's profile.

The records come from ``battgen vectors`` (the converters' conformance vectors): every vector whose input the
source's validator accepts is a record a real source could send, so its output is what battgen would hand the
target; ``battgen validate`` with the target's profile (PX4's for uORB) must find nothing in it. Without the
profile, PX4's known deviation (``max_error`` = 0, which PX4's own battery library writes too) is what is left.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from codegen.cli.main import main

# (source, target, policy, the target message, the target firmware's profile)
PAIRS = [
    ("dronecan", "uorb", "px4", "uorb.BatteryStatus", "px4"),
    ("dronecan", "uorb", "strict", "uorb.BatteryStatus", "px4"),
    ("mavlink", "uorb", "strict", "uorb.BatteryStatus", "px4"),
    ("uorb_v0", "uorb", "strict", "uorb.BatteryStatus", "px4"),
]


def _valid_inputs_outputs(tmp_path: Path, capsys: pytest.CaptureFixture[str], pair: tuple[str, ...]) -> list[object]:
    source, target, policy = pair[:3]
    out = tmp_path / "vectors.json"
    assert main(["vectors", "--from", source, "--to", target, "--policy", policy, "-o", str(out)]) == 0
    capsys.readouterr()
    doc = json.loads(out.read_text())
    (source_message,) = doc["messages"][source] if len(doc["messages"][source]) == 1 else (None,)
    outputs = []
    for vector in doc["vectors"]:
        output = vector.get("output")
        if not isinstance(output, dict):
            continue  # the converter refused this input: nothing handed on
        if source_message is not None:  # keep the vectors whose input the source's validator accepts
            record = tmp_path / "input.jsonl"
            record.write_text(json.dumps(vector["input"]) + "\n")
            if main(["validate", "--message", source_message, str(record)]) != 0:
                capsys.readouterr()
                continue
            capsys.readouterr()
        elif vector["id"] != "baseline":
            continue  # a two-message source: its baseline, a record pair every validator accepts
        outputs.append(output)
    return outputs


@pytest.mark.parametrize("pair", PAIRS, ids=["-".join(p[:3]) for p in PAIRS])
def test_converter_output_passes_under_the_targets_profile(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], pair: tuple[str, str, str, str, str]
) -> None:
    message, profile = pair[3], pair[4]
    outputs = _valid_inputs_outputs(tmp_path, capsys, pair)
    assert outputs, "no vector with a valid input"
    data = tmp_path / "out.jsonl"
    data.write_text("".join(json.dumps(o) + "\n" for o in outputs))
    code = main(["validate", "--message", message, "--profile", profile, str(data)])
    out, err = capsys.readouterr()
    assert (code, out) == (0, ""), err
    assert f"{len(outputs)} record" in err.splitlines()[-1]
    # without the profile only PX4's own known deviation is left: the profile is what makes them pass, nothing else
    code = main(["validate", "--message", message, "--profile", "", "--format", "json", str(data)])
    doc = json.loads(capsys.readouterr().out)
    rules = {f"{v['rule']}/{v['path']}" for f in doc["files"] for v in f["violations"]}
    assert rules <= {"range/max_error"}

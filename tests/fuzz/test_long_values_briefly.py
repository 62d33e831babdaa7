"""Found by the long fuzz run (read-dts): a devicetree string property thousands of characters long was quoted whole
in its finding ("is not one of ..."), so one crafted node could print a 4,594-character line. A value that is not one
of its choices, or not its constant, is quoted briefly, as every other finding quotes an input's value."""

from __future__ import annotations

from pathlib import Path

import pytest

from codegen.cli.main import main

NODE = """/dts-v1/;
/ {{
\tbattery {{
\t\tcompatible = "simple-battery";
\t\tdevice-chemistry = "{chemistry}";
\t\tcharge-full-design-microamp-hours = <5000000>;
\t}};
}};
"""


def test_a_long_value_outside_its_choices_is_quoted_briefly(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "long.dts"
    path.write_text(NODE.format(chemistry="lithium-ion-polyme" + "9" * 5000), encoding="utf-8")
    assert main(["validate", str(path)]) == 1
    out = capsys.readouterr()
    lines = (out.out + out.err).splitlines()
    (chemistry,) = [line for line in lines if "device-chemistry" in line]
    assert "is not one of 'nickel-cadmium'" in chemistry and "'lithium-ion-polyme99" in chemistry
    assert len(chemistry) < 500

"""Cross-field rule files: loading, the expression language, error paths (file, line, what was
expected) and the compiled rules' behaviour in a generated package."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

from codegen.errors import SchemaError
from codegen.frontends import rules
from codegen.frontends.loader import load
from codegen.frontends.rules.parse import ExprError, parse, parse_template
from codegen.ir import (
    ArrayType,
    Field,
    Location,
    Message,
    PrimitiveKind,
    PrimitiveType,
    Range,
    Schema,
    Sentinel,
    SourceFormat,
)
from codegen.ir.expr import Compare, Quant

ROOT = Path(__file__).resolve().parents[2]
F32 = PrimitiveType(PrimitiveKind.FLOAT, 32)
U8 = PrimitiveType(PrimitiveKind.UINT, 8)
LOC = Location("t.msg", 1)


def _write(tmp_path: Path, text: str, name: str = "r.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _error(tmp_path: Path, text: str) -> SchemaError:
    with pytest.raises(SchemaError) as info:
        rules.load_rule_file(_write(tmp_path, text), root=tmp_path)
    return info.value


GOOD = """\
messages: [uorb.T]
rules:
  - id: a-below-b
    assert: "a < b"
    message: "a = {a} must be below b = {b}"
"""


# --------------------------------------------------------------------------------------------
# The shipped rule files


def test_shipped_rules_load_and_bind() -> None:
    schema = load([ROOT / "schemas"])
    assert schema.rules, "the bundled schema folder's rules/ reaches the IR"
    names = {m.qualified_name for m in schema.messages}
    ids = []
    for rule in schema.rules:
        assert set(rule.messages) <= names, rule.location
        for qn in rule.messages:
            rules.check_binding(rule, schema.message(qn))
        ids.append(rule.id)
    for expected in (
        "voltage-design-order",
        "ocv-table-descending",
        "ocv-table-count",
        "charge-voltage-below-over-voltage",
        "design-max-below-charge-voltage",
        "cell-count-capacity",
        "cells-beyond-count-zero",
    ):
        assert expected in ids
    advice = [r for r in schema.rules if r.id == "design-max-below-charge-voltage"]
    assert advice[0].severity == "warning"
    # the OCV percent limit is the binding's own (items: items: [.., {maximum: 100}]), so no rule restates it
    assert "ocv-capacity-percent" not in ids
    table = schema.message("devicetree.power.supply.battery").field("^ocv-capacity-table-[0-9]+$").type
    assert isinstance(table, ArrayType) and isinstance(table.element, ArrayType)
    assert table.element.columns[1].range == Range(maximum=100)


# --------------------------------------------------------------------------------------------
# The expression language


def test_precedence_and_chained_comparison() -> None:
    e = parse("0 <= a + 2 * b <= 100 and not c or d")
    assert e.__class__.__name__ == "BoolOp"
    c = parse("0 <= x[1] <= 100")
    assert isinstance(c, Compare) and c.ops == ("<=", "<=")
    q = parse("all(t[i - 1][0] >= t[i][0] for i in range(1, len(t)))")
    assert isinstance(q, Quant) and q.var == "i"
    assert isinstance(parse("'x' not in `^a-[0-9]+$`"), Compare)


@pytest.mark.parametrize(
    ("text", "expected", "column"),
    [
        ("a <", "expected a value, found the end of the expression", 4),
        ("a.b", "unexpected character '.'", 2),
        ("__import__('os')", "unknown function '__import__'", 1),
        ("len(a, b)", "len() takes 1 argument(s), got 2", 1),
        ("(a", "expected ')'", 3),
        ("a b", "unexpected 'b' after a complete expression", 3),
        ("x[0", "expected ']' closing the index", 4),
        ("and", "expected a value, found the keyword 'and'", 1),
    ],
)
def test_expression_errors_name_the_column(text: str, expected: str, column: int) -> None:
    with pytest.raises(ExprError) as info:
        parse(text)
    assert expected in info.value.message and info.value.column == column


def test_template_placeholders_and_braces() -> None:
    parts = parse_template("v = {a[0]} uV {{literal}}")
    assert parts[0] == "v = " and parts[2] == " uV {literal}"
    with pytest.raises(ExprError, match="without a matching"):
        parse_template("oops {a")


# --------------------------------------------------------------------------------------------
# Malformed rule files: SchemaError with file and line, saying what was expected


@pytest.mark.parametrize(
    ("text", "line", "expected"),
    [
        ("messages: [uorb.T]\nrules: [\n", 3, "expected YAML"),
        ("", 1, "expected a rule file"),
        ("messages: [uorb.T]\nrules:\n  - id: x\n    message: m\n", 3, "'assert' is a required property"),
        (GOOD + "    colour: red\n", 3, "Additional properties are not allowed"),
        (GOOD.replace("a-below-b", "Bad Id"), 3, "does not match"),
        (GOOD + "    severity: fatal\n", 6, "is not one of ['error', 'warning']"),
        (GOOD.replace('"a < b"', '"a <"'), 4, "in 'assert' 'a <': expected a value"),
        (GOOD.replace("{a}", "{a"), 5, "in 'message'"),
        (GOOD + '    for: "x of y"\n', 6, "does not match"),
        (GOOD + '    for: "x in )"\n', 6, "in 'for' 'x in )': expected a value, found ')'"),
        ("messages: [uorb.T]\nmessages: [uorb.U]\nrules: []\n", 2, "duplicate key 'messages'"),
        ("messages: [nope.T]\nrules:\n  - {id: a, assert: a, message: m}\n", 1, "does not match"),
    ],
)
def test_malformed_rule_files(tmp_path: Path, text: str, line: int, expected: str) -> None:
    err = _error(tmp_path, text)
    assert err.file == "r.yaml" and err.line == line, str(err)
    assert expected in str(err)


def _tiny(fields: tuple[Field, ...] = ()) -> Message:
    base = (
        Field("a", F32, Location("t.msg", 2)),
        Field("b", F32, Location("t.msg", 3)),
        Field("n", U8, Location("t.msg", 4), invalid=Sentinel(0, "0")),
        Field("cells", ArrayType(F32, 4, False), Location("t.msg", 5), invalid=Sentinel(0.0, "0", per_element=True)),
    )
    return Message("T", "uorb.T", SourceFormat.UORB, LOC, "", base + fields)


@pytest.mark.parametrize(
    ("change", "line", "expected"),
    [
        (('"a < b"', '"a < zz"'), 4, "'zz' (column 5 of 'assert') is not a field, constant or loop variable of uorb.T"),
        (('"a < b"', '"is_known(a + 1)"'), 4, "is_known() takes a field name"),
        (("    message:", '    path: "a + 1"\n    message:'), 5, "expected 'path' to name a field or loop variable"),
        (("    message:", '    for: "a in range(3)"\n    message:'), 5, "loop variable 'a' hides a field"),
    ],
)
def test_binding_errors_name_the_line(tmp_path: Path, change: tuple[str, str], line: int, expected: str) -> None:
    f = rules.load_rule_file(_write(tmp_path, GOOD.replace(*change)), root=tmp_path)
    with pytest.raises(SchemaError) as info:
        rules.check_binding(f[0], _tiny())
    assert info.value.file == "r.yaml" and info.value.line == line, str(info.value)
    assert expected in str(info.value)


def test_duplicate_rule_ids_are_rejected(tmp_path: Path) -> None:
    _write(tmp_path, GOOD, "one.yaml")
    _write(tmp_path, GOOD, "two.yaml")
    found = rules.load_rules_dir(tmp_path)
    with pytest.raises(SchemaError, match=r"rule id 'a-below-b' of uorb\.T is used twice") as info:
        rules.check_unique_ids(found, "uorb.T")
    assert info.value.file == "two.yaml" and info.value.line == 3


# --------------------------------------------------------------------------------------------
# Compiled into a generated package


RULES = """\
messages: [uorb.T]
rules:
  - id: a-below-b
    assert: "a < b"
    message: "a = {a} V must be below b = {b} V"
  - id: cells-zero
    where: "is_known(n)"
    for: "i in range(n, len(cells))"
    assert: "cells[i] == 0"
    path: "cells[i]"
    message: "cell {i} = {cells[i]} V beyond n = {n}"
  - id: advice
    severity: warning
    assert: "all(c <= 4.2 for c in cells) and max(cells) - min(cells) < 5"
    message: "cells {cells} look odd"
  - id: arithmetic
    assert: "abs(a - b) // 1 != 7 and (a * 2) / 2 == a and -a <= 1e9 and sum(sorted(cells)) >= 0"
    message: "never"
"""


def _generated(tmp_path: Path, import_generated: Any, text: str = RULES) -> Any:
    folder = tmp_path / "rules"
    folder.mkdir()
    _write(folder, text)
    module = import_generated(Schema(messages=(_tiny(),), rules=rules.load_rules_dir(folder)), "uorb")
    return module.T


def test_rules_compile_into_validate(tmp_path: Path, import_generated: Any) -> None:
    T = _generated(tmp_path, import_generated)
    assert T(a=1.0, b=2.0, n=2, cells=[4.0, 4.0, 0.0, 0.0]).validate() == []
    found = T(a=3.0, b=2.0, n=2, cells=[4.0, 4.0, 3.9, 0.0]).validate()
    by_rule = {v.rule: v for v in found}
    assert by_rule["cross-field:a-below-b"].message == "a = 3 V must be below b = 2 V"
    assert by_rule["cross-field:a-below-b"].path == "a"
    cell = by_rule["cross-field:cells-zero"]
    assert (cell.path, cell.value, cell.limit) == ("cells[2]", 3.9, "cells[i] == 0")
    assert cell.message == "cell 2 = 3.9 V beyond n = 2"
    # where: n unknown (its sentinel 0) skips the rule
    assert T(a=1.0, b=2.0, n=0, cells=[4.0, 4.0, 3.9, 0.0]).validate() == []


def test_warnings_do_not_fail_check(tmp_path: Path, import_generated: Any) -> None:
    T = _generated(tmp_path, import_generated)
    t = T(a=1.0, b=2.0, n=4, cells=[4.3, 4.0, 4.0, 4.0])
    found = t.validate()
    assert [(v.rule, v.severity) for v in found] == [("cross-field:advice", "warning")]
    t.check()  # warnings only: no exception
    t.a = 5.0
    with pytest.raises(ValueError) as info:
        t.check()
    assert len(info.value.violations) == 2  # type: ignore[attr-defined]
    assert [v.rule for v in info.value.errors] == ["cross-field:a-below-b"]  # type: ignore[attr-defined]


def test_a_rule_that_cannot_be_evaluated_is_skipped(tmp_path: Path, import_generated: Any) -> None:
    T = _generated(tmp_path, import_generated)
    t = T(a=1.0, b=2.0, n=2, cells=[4.0, "x", 0.0, 0.0])
    found = t.validate()
    # the field check reports the cause; the rules reading cells do not crash
    assert [v.rule for v in found] == ["type"] and found[0].path == "cells[1]"
    t = T(a=math.nan, b=2.0)
    assert [v.rule for v in t.validate()] == ["nan", "cross-field:a-below-b", "cross-field:arithmetic"]


def test_no_rules(tmp_path: Path, import_generated: Any) -> None:
    module = import_generated(Schema(messages=(_tiny(),)), "uorb")
    assert module.T(a=3.0, b=2.0).validate() == []


def test_rules_naming_an_undefined_message_of_a_loaded_format_are_rejected(tmp_path: Path) -> None:
    from codegen.frontends.loader import load as load_folder

    (tmp_path / "uorb").mkdir()
    (tmp_path / "uorb" / "T.msg").write_text("uint64 timestamp\nfloat32 a\nfloat32 b\n", encoding="utf-8")
    (tmp_path / "rules").mkdir()
    _write(tmp_path / "rules", GOOD.replace("uorb.T", "uorb.Missing"))
    with pytest.raises(SchemaError, match=r"names uorb\.Missing, which is not defined") as info:
        load_folder([tmp_path])
    assert info.value.file == "r.yaml"


def test_rules_travel_with_the_schema_folder(tmp_path: Path) -> None:
    from codegen.frontends.loader import load as load_folder

    (tmp_path / "uorb").mkdir()
    (tmp_path / "uorb" / "T.msg").write_text("uint64 timestamp\nfloat32 a\nfloat32 b\n", encoding="utf-8")
    assert load_folder([tmp_path]).rules == ()  # no rules/ folder: no rules, bundled or otherwise
    (tmp_path / "rules").mkdir()
    _write(tmp_path / "rules", GOOD)
    assert [r.id for r in load_folder([tmp_path]).rules] == ["a-below-b"]

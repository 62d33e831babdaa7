from __future__ import annotations

import pytest

from codegen.ir import units


@pytest.mark.parametrize(
    ("spelling", "symbol"),
    [
        ("V", "V"),
        ("Volt", "V"),
        ("mV", "mV"),
        ("microvolt", "uV"),
        ("°C", "degC"),
        ("degC", "degC"),
        ("Kelvin", "K"),
        ("cdegC", "cdegC"),
        ("Watt hours", "Wh"),
        ("mAh", "mAh"),
        ("hJ", "hJ"),
        ("cA", "cA"),
        ("%", "%"),
        ("minutes", "min"),
        ("Ohm", "Ohm"),
        ("us", "us"),
        ("Hours", "h"),
        ("Ampere", "A"),
    ],
)
def test_spellings_resolve(spelling: str, symbol: str) -> None:
    unit = units.lookup(spelling)
    assert unit is not None and unit.symbol == symbol


def test_milli_and_mega_are_not_confused() -> None:
    assert units.lookup("mA") is not None and units.lookup("mA").scale == pytest.approx(1e-3)  # type: ignore[union-attr]
    assert units.lookup("MA") is None


@pytest.mark.parametrize(
    ("src", "dst", "value", "expected"),
    [
        ("mV", "V", 12600, 12.6),
        ("uV", "mV", 4_200_000, 4200),
        ("K", "degC", 298.15, 25.0),
        ("degC", "cdegC", 25.0, 2500),
        ("cdegC", "K", 2510, 298.25),
        ("uAh", "mAh", 1_430_000, 1430),
        ("Wh", "hJ", 1.0, 36.0),
        ("uWh", "Wh", 5_290_000, 5.29),
        ("cA", "A", 32767, 327.67),
        ("%", "1", 50, 0.5),
        ("min", "s", 2, 120),
    ],
)
def test_factors_derive_from_the_registry(src: str, dst: str, value: float, expected: float) -> None:
    mul, add = units.unit(src).factor_to(units.unit(dst))
    assert value * mul + add == pytest.approx(expected)


def test_incompatible_quantities_refuse() -> None:
    with pytest.raises(ValueError, match="cannot convert"):
        units.unit("V").factor_to(units.unit("A"))


@pytest.mark.parametrize(
    ("prop", "symbol"),
    [
        ("voltage-min-design-microvolt", "uV"),
        ("charge-full-design-microamp-hours", "uAh"),
        ("energy-full-design-microwatt-hours", "uWh"),
        ("factory-internal-resistance-micro-ohms", "uOhm"),
        ("operating-range-celsius", "degC"),
        ("volt-drop-temperatures-millicelsius", "mdegC"),
        ("volt-drop-soc-bp", "bp"),
        ("precharge-current-microamp", "uA"),
    ],
)
def test_devicetree_suffixes(prop: str, symbol: str) -> None:
    unit = units.devicetree_suffix_unit(prop)
    assert unit is not None and unit.symbol == symbol


def test_unknown_unit_is_opaque_not_convertible() -> None:
    assert units.lookup("furlong/fortnight") is None
    opaque = units.opaque("furlong/fortnight")
    with pytest.raises(ValueError):
        opaque.factor_to(units.unit("m/s"))

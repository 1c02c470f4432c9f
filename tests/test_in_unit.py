"""units.in_unit: an SI value written in a unit people type (parse_value's inverse)."""

import math

import pytest

from screwkin.units import in_unit, parse_value


@pytest.mark.parametrize("si, unit, expected", [
    (math.pi, "deg", 180.0),  # pi rad is half a turn
    (0.03, "mm", 30.0),
    (2 * math.pi, "rpm", 60.0),  # one turn a second
    (0.5, "rad", 0.5),
])
def test_in_unit_by_definition(si, unit, expected):
    assert in_unit(si, unit) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("number, unit", [("45", "deg"), ("30", "mm"), ("60", "rpm"), ("1.5", "in")])
def test_in_unit_undoes_parse_value(number, unit):
    assert in_unit(parse_value(number + unit), unit) == pytest.approx(float(number), rel=1e-12)

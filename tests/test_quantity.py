"""A typed value travels as one units.Quantity from parsing to the table (issue 37 item 4): parsed once,
with its SI value, its kind and the unit typed; shown back in that unit by one rule (units.shown_unit)
and one conversion (units.in_unit).  The references are the units' definitions (1 deg = pi/180 rad,
1 rpm = 2 pi/60 rad/s, 1 mm = 1e-3 m) and the number a person typed coming back.

units.in_unit: an SI value written in a unit people type (parse_value's inverse)."""

from __future__ import annotations

import math

import pytest
from conftest import ROBOTS

from screwkin.cli import main
from screwkin.units import Quantity, in_unit, parse_quantity, parse_typed_assignments, parse_value, shown_unit

FOURBAR = str(ROBOTS / "fourbar_crank_rocker.urdf")


@pytest.mark.parametrize("text, value, kind, unit", [
    ("30MM", 0.03, "length", "mm"), ("45 Deg", math.pi / 4, "angle", "deg"), ("0.5", 0.5, None, ""),
    ("60rpm", 2 * math.pi, "angular rate", "rpm"), ("2kN", 2000.0, "force", "kN"), ("1turn", 2 * math.pi, "angle", "turn"),
])
def test_a_value_is_parsed_once_into_its_quantity(text, value, kind, unit):
    q = parse_quantity(text)
    assert (q.kind, q.unit) == (kind, unit)
    assert q.value == pytest.approx(value, rel=1e-15)
    assert parse_quantity(text, kind="length" if kind == "length" else None).value == q.value


@pytest.mark.parametrize("typed, kind, shown", [
    # a unit of the kind itself: as typed, its case made the table's
    ("DEG", "angle", "deg"), ("mm", "length", "mm"), ("rev/min", "angular rate", "rpm"),
    ("deg/s2", "angular acceleration", "deg/s^2"),
    # an angle or length typed for a rate or acceleration: per second (the old meaning of --rate crank=90deg)
    ("deg", "angular rate", "deg/s"), ("deg", "angular acceleration", "deg/s^2"), ("mm", "linear rate", "mm/s"),
    ("cm", "linear acceleration", "cm/s^2"), ("rev", "angular rate", "rev/s"),
    # a rate's unit for its acceleration: per second
    ("rpm", "angular acceleration", "rpm/s"), ("deg/s", "angular acceleration", "deg/s^2"),
    ("rev/s", "angular acceleration", "rev/s^2"), ("mm/s", "linear acceleration", "mm/s^2"),
    # no such unit (turn/s, in/s are not units screwkin reads), or none typed: SI
    ("turn", "angular rate", "rad/s"), ("in", "linear rate", "m/s"), ("", "angular acceleration", "rad/s^2"),
    ("", "length", "m"), ("", None, ""),
])
def test_the_one_rule_of_the_unit_shown(typed, kind, shown):
    assert shown_unit(typed, kind) == shown
    if shown:  # every unit shown is one screwkin reads back: the table's numbers can be typed again
        assert parse_quantity("1" + shown).value > 0


@pytest.mark.parametrize("typed, number", [("90deg", 90.0), ("120rpm", 120.0), ("5mm", 5.0), ("2rev/s", 2.0),
                                           ("0.75", 0.75), ("1turn", None)])
def test_a_rate_typed_comes_back_as_typed(typed, number):
    """--rate crank=90deg is 90 deg/s: shown in deg/s it is 90 again; 1turn for a rate has no turn/s form,
    shown in rad/s it is 2 pi."""
    kind = "linear rate" if typed.endswith("mm") else "angular rate"
    q = Quantity(parse_quantity(typed).value, kind, parse_quantity(typed).unit)
    expected = 2 * math.pi if number is None else number
    assert in_unit(q.value, q.shown_unit) == pytest.approx(expected, rel=1e-12)
    assert q.text() == f"{expected:.6g} {q.shown_unit}"


def test_assignments_keep_each_quantity():
    got = parse_typed_assignments(["a=45deg", "b,c=2MM", "d=0.5"], "--set")
    assert [(n, q.unit, q.kind) for n, q in got] == [("a", "deg", "angle"), ("b", "mm", "length"),
                                                      ("c", "mm", "length"), ("d", "", None)]
    assert got[0][1].value == pytest.approx(math.pi / 4) and got[1][1].value == pytest.approx(0.002)


def test_the_tables_answer_in_the_units_typed(capsys):
    """solve --rate crank_joint=90deg: omega in deg/s, alpha in deg/s^2 (the crank's own omega is the 90
    typed); sweep --to 90deg: the input in degrees; --rate 1turn (no turn/s): SI, said in words."""
    assert main(["solve", FOURBAR, "--set", "crank_joint=30deg", "--rate", "crank_joint=90deg"]) == 0
    out = capsys.readouterr().out
    head = next(line for line in out.splitlines() if line.startswith("link "))
    assert "omega [deg/s]" in head and "alpha [deg/s^2]" in head
    crank = next(line.split() for line in out.splitlines() if line.startswith("crank "))
    assert float(crank[2]) == pytest.approx(90.0, rel=1e-6)
    assert main(["sweep", FOURBAR, "--input", "crank_joint", "--from", "0", "--to", "90deg", "--steps", "2",
                 "--rate", "1turn"]) == 0
    out = capsys.readouterr().out
    assert "at crank_joint 6.28319 rad/s" in out and "input [deg]" in out  # --to 90deg: the input in degrees


# ---------------------------------------------------------------- folded in from test_in_unit.py
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

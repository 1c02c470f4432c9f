"""Values typed by people: numbers with an optional unit suffix, converted to SI.

``45deg`` -> 0.785398... rad, ``30mm`` -> 0.03 m, ``0.5`` -> 0.5 (SI as typed).
Rates and accelerations take the same suffixes (``90deg`` in ``--rate`` means
90 deg/s).

Units (a space between number and unit is allowed, ``30 mm``; ASCII units are
case-insensitive, ``30MM``, ``45Deg``, ``2KN``, except where two differ by case only:
``nm`` is a nanometre, ``Nm`` a newton metre, and ``NM`` is an error):

* angles: ``rad`` (``radian(s)``), ``mrad``, ``deg`` (``degree(s)``, ``°``),
  ``turn(s)`` (one full revolution, 2 pi rad);
* lengths: ``m``, ``cm``, ``mm``, ``um`` (``µm``, ``μm``), ``nm``, ``in`` (``inch``,
  ``inches``: 25.4 mm), ``ft`` (``foot``, ``feet``: 0.3048 m);
* rates: ``rad/s``, ``deg/s``, ``rpm`` (``rev/min``), ``rev/s``; ``m/s``, ``mm/s``, ``cm/s``;
* accelerations: ``rad/s^2``, ``deg/s^2``, ``rpm/s``, ``rev/s^2``; ``m/s^2``, ``mm/s^2``, ``cm/s^2`` (``s2`` for
  ``s^2``);
* forces and moments: ``N``, ``kN``, ``mN``; ``Nm`` (``N*m``, ``N.m``), ``kNm``, ``Nmm``.

Every unit has a kind (:data:`UNIT_TABLE`); where a value's kind is known (a joint's value,
a length, a rate) a unit of another kind is a usage error.  An angle or length given for a
rate keeps its old meaning (``--rate crank=90deg`` is 90 deg/s).

A value is parsed once, into a :class:`Quantity`: its value in SI, its kind and the unit typed,
carried to the table that shows it.  How a value is shown is decided here and nowhere else:
:func:`shown_unit` (the unit a value of a kind is shown in, from the unit a person typed:
``deg`` typed for a rate shows rates in deg/s and accelerations in deg/s^2, ``rpm`` shows
accelerations in rpm/s) and :func:`in_unit` (an SI value in a unit).  pint was considered and
not taken: importing it and building its registry take about 0.35 s, more than the whole start-up
of the command line (0.2 s), and it knows neither the kinds an option takes nor the refusals above.

Kilometres are not accepted on purpose (no mechanism is that big: ``1km`` is
more likely a typo than a value).  Numbers are plain decimal ASCII (``1e-3``,
``.5``); ``nan``, ``inf`` and ``1_000`` are refused.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from .errors import UsageError, quote
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np

__all__ = ["Quantity", "parse_quantity", "parse_value", "in_unit", "unit_text", "shown_unit", "parse_length",
           "parse_typed_assignments", "UNITS", "UNIT_TABLE", "unit_kind", "LENGTH_RANGE", "MAGNITUDES",
           "check_magnitude"]

_DEG = math.pi / 180.0
_TURN = 2 * math.pi
#: unit -> (factor to SI, kind).  Kinds: angle, length, angular rate, linear rate, angular
#: acceleration, linear acceleration, force, moment.
UNIT_TABLE = {
    "rad": (1.0, "angle"), "radian": (1.0, "angle"), "radians": (1.0, "angle"), "mrad": (1e-3, "angle"),
    "deg": (_DEG, "angle"), "degree": (_DEG, "angle"), "degrees": (_DEG, "angle"), "°": (_DEG, "angle"),
    "turn": (_TURN, "angle"), "turns": (_TURN, "angle"), "rev": (_TURN, "angle"),
    "m": (1.0, "length"), "cm": (0.01, "length"), "mm": (0.001, "length"), "um": (1e-6, "length"),
    "µm": (1e-6, "length"), "μm": (1e-6, "length"), "nm": (1e-9, "length"),
    "in": (0.0254, "length"), "inch": (0.0254, "length"), "inches": (0.0254, "length"),
    "ft": (0.3048, "length"), "foot": (0.3048, "length"), "feet": (0.3048, "length"),
    "rad/s": (1.0, "angular rate"), "deg/s": (_DEG, "angular rate"), "rpm": (_TURN / 60.0, "angular rate"),
    "rev/s": (_TURN, "angular rate"), "rev/min": (_TURN / 60.0, "angular rate"),
    "m/s": (1.0, "linear rate"), "mm/s": (1e-3, "linear rate"), "cm/s": (1e-2, "linear rate"),
    "rad/s^2": (1.0, "angular acceleration"), "deg/s^2": (_DEG, "angular acceleration"),
    "rad/s2": (1.0, "angular acceleration"), "deg/s2": (_DEG, "angular acceleration"),
    "rpm/s": (_TURN / 60.0, "angular acceleration"), "rev/s^2": (_TURN, "angular acceleration"),
    "rev/s2": (_TURN, "angular acceleration"),
    "m/s^2": (1.0, "linear acceleration"), "mm/s^2": (1e-3, "linear acceleration"),
    "m/s2": (1.0, "linear acceleration"), "mm/s2": (1e-3, "linear acceleration"),
    "cm/s^2": (1e-2, "linear acceleration"), "cm/s2": (1e-2, "linear acceleration"),
    "N": (1.0, "force"), "kN": (1e3, "force"), "mN": (1e-3, "force"),
    "Nm": (1.0, "moment"), "N*m": (1.0, "moment"), "N.m": (1.0, "moment"), "kNm": (1e3, "moment"),
    "Nmm": (1e-3, "moment"), "N*mm": (1e-3, "moment"),
}
UNITS = {"": 1.0, **{u: f for u, (f, _) in UNIT_TABLE.items()}}
_CASE = {}  # lower case -> the unit ("KN" -> "kN", "RPM" -> "rpm"), or a tuple when two units differ by case only
for _u in UNIT_TABLE:
    if _u.isascii():
        _CASE.setdefault(_u.lower(), []).append(_u)
_CASE = {k: v[0] if len(v) == 1 else tuple(v) for k, v in _CASE.items()}
#: The smallest and largest characteristic length, grid step or other mechanism length a person may type [m]:
#: below a nanometre the measures divided by it overflow; no mechanism is 10 km long.
LENGTH_RANGE = (1e-9, 1e4)


def _canonical(unit: str):
    if unit in UNIT_TABLE:
        return unit
    u = _CASE.get(unit.lower()) if unit.isascii() else None
    if isinstance(u, tuple):  # NM: nanometre or newton metre -- not a guess
        raise UsageError(f"unit {quote(unit, 20)} is ambiguous: write {' or '.join(u)} ("
                         + ", ".join(UNIT_TABLE[x][1] for x in u) + ")")
    return u


#: The largest magnitude a value of each kind may have [SI]: beyond any machine, and small enough that the
#: squares and products the analyses form stay finite (--gravity 1e300 gave inf reactions, --speed 1e308rpm
#: NaN efforts, --wrench 1e308 an effort of 0).  A length is held to a mechanism file's positions
#: (files/description.LIMITS.length, 10 km); an angle to 1e5 rad (15,915 turns: beyond it a double keeps no
#: place in a turn); a rate to 1e5 rad/s (955,000 rpm) or 1e4 m/s; an acceleration to 1e8 rad/s^2 or
#: 1e7 m/s^2 (a million g); a force to 1e10 N and a moment to 1e10 N m (a million tonnes' weight).
MAGNITUDES = {"length": 1e4, "angle": 1e5, "angular rate": 1e5, "linear rate": 1e4, "angular acceleration": 1e8,
              "linear acceleration": 1e7, "force": 1e10, "moment": 1e10}
_SI = {"length": "m", "angle": "rad", "angular rate": "rad/s", "linear rate": "m/s", "angular acceleration": "rad/s^2",
       "linear acceleration": "m/s^2", "force": "N", "moment": "N m"}


def check_magnitude(value: float, kind: str, what: str) -> float:
    """``value`` [SI] when its magnitude is within MAGNITUDES[kind]; a usage error naming ``what`` otherwise."""
    bound = MAGNITUDES.get(kind)
    if bound is not None and abs(value) > bound:
        article = "an" if kind[0] in "aeiou" else "a"
        raise UsageError(f"{what}: {value:g} {_SI[kind]} is beyond the {bound:g} {_SI[kind]} {article} {kind} may have "
                         "here")
    return value


def unit_kind(unit: str) -> str | None:
    """The kind of a unit ('angle', 'length', 'angular rate', ...), or None for a bare number."""
    if not unit:
        return None
    u = _canonical(unit)
    return UNIT_TABLE[u][1] if u else None


_NUMBER = re.compile(r"\s*([-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?)\s*(\S*)\s*\Z")


def _unit(text: str):
    """The factor of a unit as typed (case-insensitive for ASCII units), or None."""
    if not text:
        return 1.0
    u = _canonical(text)
    return UNIT_TABLE[u][0] if u else None


@dataclass(frozen=True)
class Quantity:
    """A value as a person typed it, parsed once: ``value`` in SI, ``kind`` what it is ('angle',
    'length', 'angular rate', ...: the kind its place gives it, else its unit's; None for a bare
    number of no known kind), ``unit`` the unit typed ('' when bare; 'DEG' is 'deg')."""

    value: float
    kind: str | None = None
    unit: str = ""

    @property
    def shown_unit(self) -> str:
        """The unit this value, and others of its kind, are shown in (:func:`shown_unit`)."""
        return shown_unit(self.unit, self.kind)

    def text(self, value: float | None = None, digits: int = 6) -> str:
        """This value (or ``value`` [SI], of the same kind) in :attr:`shown_unit`: ``30 deg``, ``60 rpm``."""
        return unit_text(self.value if value is None else value, self.shown_unit, digits)


def parse_quantity(text: str, kind: str | None = None, option: str | None = None) -> Quantity:
    """A number with an optional unit suffix: its value in SI, its kind and the unit typed.  With
    ``kind`` ('angle', 'length', ...), a unit of another kind is a usage error naming ``option``
    (``--length 90deg`` is not 1.571 m), and a magnitude beyond MAGNITUDES[kind] another."""
    m = _NUMBER.match(text)
    if not m:
        raise UsageError(f"{quote(text)} is not a number with an optional unit (e.g. 45deg, 30mm, 1in, 0.5)")
    factor = _unit(m.group(2))
    if factor is None:
        known = ", ".join(u for u in ("rad", "mrad", "deg", "°", "turn", "m", "cm", "mm", "um", "in", "ft", "rpm",
                                      "deg/s", "mm/s", "m/s^2", "N", "kN", "N*m"))
        raise UsageError(f"unknown unit {quote(m.group(2), 20)} in {quote(text)} (known: {known})")
    value = float(m.group(1)) * factor
    if not math.isfinite(value):
        raise UsageError(f"{quote(text)} is not a finite number")
    found = unit_kind(m.group(2))
    if kind is not None and found is not None and found != kind:
        where = f"{option} " if option else ""
        raise UsageError(f"{where}{quote(text)}: {m.group(2)} is a unit of {found}, {where.strip() or 'this value'} "
                         f"takes {'an' if kind[0] in 'aeiou' else 'a'} {kind}")
    if kind is not None:
        check_magnitude(value, kind, f"{option} {quote(text, 40)}" if option else quote(text, 40))
    return Quantity(value, kind or found, _canonical(m.group(2)) if m.group(2) else "")


def parse_value(text: str, kind: str | None = None, option: str | None = None) -> float:
    """The SI value of a number with an optional unit suffix (:func:`parse_quantity`)."""
    return parse_quantity(text, kind, option).value


def in_unit(value: np.ndarray | float, unit: str) -> np.ndarray | float:
    """An SI value (or an array of them) written in ``unit`` as people type it, parse_value's inverse
    (``in_unit(math.pi, "deg")`` is 180.0, ``in_unit(0.03, "mm")`` is 30.0; SI for '')."""
    return value / parse_value("1" + unit.replace(" ", ""))


def si_factor(unit: str) -> float:
    """The number 1 SI (1 rad/s, 1 m) written in ``unit`` ('deg/s²' read as 'deg/s^2'); 1 for a number
    without a unit."""
    return in_unit(1.0, unit.replace("²", "^2")) if unit else 1.0


def unit_text(value: float, unit: str, digits: int = 6) -> str:
    """``value`` [SI] written in ``unit``: ``unit_text(math.pi / 6, "deg")`` is '30 deg' (the bare
    number for no unit)."""
    return f"{in_unit(value, unit):.{digits}g} {unit}" if unit else f"{value:.{digits}g}"


#: The kind a value's rate has (the rate of an angle is an angular rate), and an acceleration's.
_RATE_OF = {"angle": "angular rate", "length": "linear rate", "angular rate": "angular acceleration",
           "linear rate": "linear acceleration"}


#: Spellings of one unit, written as the tables write it.
_SPELLED = {"degree": "deg", "degrees": "deg", "°": "deg", "radian": "rad", "radians": "rad", "turns": "turn",
            "µm": "um", "μm": "um", "inch": "in", "inches": "in", "foot": "ft", "feet": "ft",
            "rev/min": "rpm", "N*m": "Nm", "N.m": "Nm", "N*mm": "Nmm"}


def _written(unit: str) -> str:
    """A unit as the tables write it: one spelling of each (degrees and ° as deg, rev/min as rpm), s2 as s^2."""
    unit = _SPELLED.get(unit, unit)
    return unit[:-2] + "s^2" if unit.endswith("/s2") else unit


def shown_unit(typed: str, kind: str | None) -> str:
    """The unit a value of ``kind`` is shown in when a person typed ``typed`` for it, or for the value
    it is the rate or acceleration of: the unit typed when it is of that kind; an angle's or a
    length's unit made a rate or an acceleration (``deg``: deg/s, deg/s^2; ``mm``: mm/s, mm/s^2); a
    rate's unit made an acceleration (``rpm``: rpm/s; ``deg/s``: deg/s^2); the SI unit of the kind
    otherwise (``turn`` typed for a rate: rad/s, there being no turn/s), '' for a bare number of no
    known kind."""
    unit = _canonical(typed) if typed else None
    found = UNIT_TABLE[unit][1] if unit else None
    si = _SI.get(kind, "") if kind else ""
    if found is None or kind is None or found == kind:
        return _written(unit) if unit else si
    if _RATE_OF.get(found) == kind:  # deg for a rate: deg/s; rpm for an acceleration: rpm/s
        base = _written(unit)
        made = base[:-2] + "/s^2" if base.endswith("/s") else base + "/s"
    elif _RATE_OF.get(_RATE_OF.get(found)) == kind:  # deg for an acceleration: deg/s^2
        made = _written(unit) + "/s^2"
    else:
        return si
    return made if made in UNIT_TABLE else si


def parse_length(text: str, option: str) -> float:
    """A length a person types (``30mm``, ``0.1``), positive and within :data:`LENGTH_RANGE`."""
    value = parse_value(text, "length", option)
    lo, hi = LENGTH_RANGE
    if not lo <= value <= hi:
        raise UsageError(f"{option} {quote(text)}: give a length from {lo:g} m to {hi:g} m")
    return value


def parse_typed_assignments(items: list | None, option: str) -> list:
    """``["a=45deg", "b=0.1,c=2mm"]`` -> ``[("a", Quantity(0.785..., "angle", "deg")), ("b", Quantity(0.1)),
    ("c", Quantity(0.002, "length", "mm"))]``: each value parsed once, with the unit as typed (to answer
    in the units a person used).  Several names may share one value: ``"leg1,leg2,leg3=0.41"`` gives
    each of the three 0.41."""
    out = []
    for item in items or []:
        pending = []  # names before a comma, waiting for the value of the next NAME=VALUE
        for part in item.split(","):
            if not part.strip():
                continue
            name, sep, value = part.rpartition("=")  # a value has no '=', a name may (=SUM(A1) is a name)
            if not sep:
                pending.append(part.strip())
                continue
            if not name.strip():
                raise UsageError(f"{option} expects NAME=VALUE, got {quote(part)}")
            typed = parse_quantity(value)
            for n in (*pending, name.strip()):
                if any(n == m for m, _ in out):  # the last would win without a word
                    raise UsageError(f"{option}: {quote(n)} is given twice")
                out.append((n, typed))
            pending = []
        if pending:
            raise UsageError(f"{option} expects NAME=VALUE (or NAME,NAME=VALUE), got {quote(item)}: "
                             f"no value for {quote(', '.join(pending))}")
    return out

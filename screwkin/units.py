"""Values typed by people: numbers with an optional unit suffix, converted to SI.

``45deg`` -> 0.785398... rad, ``30mm`` -> 0.03 m, ``0.5`` -> 0.5 (SI as typed).
Rates and accelerations take the same suffixes (``90deg`` in ``--rate`` means
90 deg/s).

Units (a space between number and unit is allowed, ``30 mm``; ASCII units are
case-insensitive, ``30MM``, ``45Deg``):

* angles: ``rad`` (``radian(s)``), ``mrad``, ``deg`` (``degree(s)``, ``°``),
  ``turn(s)`` (one full revolution, 2 pi rad);
* lengths: ``m``, ``cm``, ``mm``, ``um`` (``µm``, ``μm``), ``in`` (``inch``,
  ``inches``: 25.4 mm), ``ft`` (``foot``, ``feet``: 0.3048 m).

Kilometres are not accepted on purpose (no mechanism is that big: ``1km`` is
more likely a typo than a value).  Numbers are plain decimal ASCII (``1e-3``,
``.5``); ``nan``, ``inf`` and ``1_000`` are refused.
"""

from __future__ import annotations

import math
import re

from .errors import UsageError, quote

__all__ = ["parse_value", "parse_typed_value", "parse_length", "parse_assignments", "UNITS", "unit_kind", "LENGTH_RANGE"]

_DEG = math.pi / 180.0
UNITS = {
    "": 1.0,
    "rad": 1.0, "radian": 1.0, "radians": 1.0, "mrad": 1e-3,
    "deg": _DEG, "degree": _DEG, "degrees": _DEG, "°": _DEG,
    "turn": 2 * math.pi, "turns": 2 * math.pi,
    "m": 1.0, "cm": 0.01, "mm": 0.001, "um": 1e-6, "µm": 1e-6, "μm": 1e-6,
    "in": 0.0254, "inch": 0.0254, "inches": 0.0254,
    "ft": 0.3048, "foot": 0.3048, "feet": 0.3048,
}
_ANGLES = {"rad", "radian", "radians", "mrad", "deg", "degree", "degrees", "°", "turn", "turns"}
#: The smallest and largest characteristic length, grid step or other mechanism length a person may type [m]:
#: below a nanometre the measures divided by it overflow; no mechanism is 10 km long.
LENGTH_RANGE = (1e-9, 1e4)


def unit_kind(unit: str):
    """'angle', 'length', or None for a bare number (SI of whatever is asked)."""
    if not unit:
        return None
    return "angle" if (unit if unit in UNITS else unit.lower()) in _ANGLES else "length"


_NUMBER = re.compile(r"\s*([-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?)\s*(\S*)\s*\Z")


def _unit(text: str):
    """The factor of a unit as typed (case-insensitive for ASCII units), or None."""
    if text in UNITS:
        return UNITS[text]
    return UNITS.get(text.lower()) if text.isascii() else None


def parse_value(text: str, kind: str | None = None, option: str | None = None) -> float:
    """A number with an optional unit suffix, in SI units.  With ``kind`` ('angle' or
    'length'), a unit of the other kind is a usage error naming ``option``
    (``--length 90deg`` is not 1.571 m)."""
    m = _NUMBER.match(text)
    if not m:
        raise UsageError(f"{quote(text)} is not a number with an optional unit (e.g. 45deg, 30mm, 1in, 0.5)")
    factor = _unit(m.group(2))
    if factor is None:
        known = ", ".join(u for u in ("rad", "mrad", "deg", "°", "turn", "m", "cm", "mm", "um", "in", "ft"))
        raise UsageError(f"unknown unit {quote(m.group(2), 20)} in {quote(text)} (known: {known})")
    value = float(m.group(1)) * factor
    if not math.isfinite(value):
        raise UsageError(f"{quote(text)} is not a finite number")
    found = unit_kind(m.group(2))
    if kind is not None and found is not None and found != kind:
        where = f"{option} " if option else ""
        raise UsageError(f"{where}{quote(text)}: {m.group(2)} is a unit of {found}, {where.strip() or 'this value'} "
                         f"takes a {kind}")
    return value


def parse_length(text: str, option: str) -> float:
    """A length a person types (``30mm``, ``0.1``), positive and within :data:`LENGTH_RANGE`."""
    value = parse_value(text, "length", option)
    lo, hi = LENGTH_RANGE
    if not lo <= value <= hi:
        raise UsageError(f"{option} {quote(text)}: give a length from {lo:g} m to {hi:g} m")
    return value


def parse_typed_value(text: str) -> tuple:
    """``"-90deg"`` -> ``(-1.5707..., "deg")``: the value in SI and the unit as typed ("" when bare)."""
    value = parse_value(text)
    return value, _NUMBER.match(text).group(2)


def parse_typed_assignments(items, option: str) -> list:
    """``["a=45deg", "b=0.1,c=2mm"]`` -> ``[("a", 0.785..., "deg"), ("b", 0.1, ""), ("c", 0.002, "mm")]``:
    each value in SI with the unit as typed (to answer in the units a person used).  Several names
    may share one value: ``"leg1,leg2,leg3=0.41"`` gives each of the three 0.41."""
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
            typed = parse_typed_value(value)
            out += [(n, *typed) for n in (*pending, name.strip())]
            pending = []
        if pending:
            raise UsageError(f"{option} expects NAME=VALUE (or NAME,NAME=VALUE), got {quote(item)}: "
                             f"no value for {quote(', '.join(pending))}")
    return out


def parse_assignments(items, option: str) -> dict:
    """``["a=45deg", "b=0.1,c=2mm"]`` -> ``{"a": 0.785..., "b": 0.1, "c": 0.002}``."""
    return {name: value for name, value, _ in parse_typed_assignments(items, option)}

"""Values typed by people: numbers with an optional unit suffix, converted to SI.

``45deg`` -> 0.785398... rad, ``30mm`` -> 0.03 m, ``0.5`` -> 0.5 (SI as typed).
Rates and accelerations take the same suffixes (``90deg`` in ``--rate`` means
90 deg/s).
"""

from __future__ import annotations

import math
import re

from .errors import UsageError

__all__ = ["parse_value", "parse_assignments", "UNITS"]

UNITS = {
    "": 1.0, "rad": 1.0, "deg": math.pi / 180.0, "°": math.pi / 180.0,
    "m": 1.0, "cm": 0.01, "mm": 0.001, "um": 1e-6,
}
_NUMBER = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([a-zA-Z°]*)\s*$")


def parse_value(text: str) -> float:
    """A number with an optional unit suffix, in SI units."""
    m = _NUMBER.match(text)
    if not m:
        raise UsageError(f"'{text}' is not a number with an optional unit (e.g. 45deg, 30mm, 0.5)")
    unit = m.group(2)
    if unit not in UNITS:
        raise UsageError(f"unknown unit '{unit}' in '{text}' (known: {', '.join(u for u in UNITS if u)})")
    value = float(m.group(1)) * UNITS[unit]
    if not math.isfinite(value):
        raise UsageError(f"'{text}' is not a finite number")
    return value


def parse_assignments(items, option: str) -> dict:
    """``["a=45deg", "b=0.1,c=2mm"]`` -> ``{"a": 0.785..., "b": 0.1, "c": 0.002}``."""
    out = {}
    for item in items or []:
        for part in item.split(","):
            if not part.strip():
                continue
            name, sep, value = part.partition("=")
            if not sep or not name.strip():
                raise UsageError(f"{option} expects NAME=VALUE, got '{part}'")
            out[name.strip()] = parse_value(value)
    return out

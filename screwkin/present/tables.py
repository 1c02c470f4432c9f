"""Plain-text tables and number formatting shared by every text report."""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass

from ..units import in_unit, unit_kind

__all__ = ["table", "shown", "fmt_vec", "column_text", "csv_cell", "csv_text", "SHOWN_ZERO", "RateUnits",
           "input_rate_words"]

#: Display cut-off: a number smaller than this in magnitude is written as 0 (round-off is not a value).
SHOWN_ZERO = 1e-12


def table(headers, rows) -> str:
    """A plain-text table with aligned columns."""
    rows = [[str(c) for c in r] for r in rows]
    widths = [max(len(str(h)), *(len(r[i]) for r in rows)) if rows else len(str(h)) for i, h in enumerate(headers)]
    line = "  ".join(str(h).ljust(w) for h, w in zip(headers, widths)).rstrip()
    out = [line, "  ".join("-" * w for w in widths)]
    out += ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
    return "\n".join(out)


def shown(x, below: float = SHOWN_ZERO) -> float:
    """x as written: 0.0 where its magnitude is below ``below``, and never -0.0."""
    return (0.0 if abs(x) < below else x) + 0.0


def fmt_vec(v, width=11):
    """Numbers with 6 significant digits; round-off below SHOWN_ZERO shows as 0."""
    return " ".join(f"{shown(x):>{width}.6g}" for x in v)


def column_text(values, relative: float = 1e-9, absolute: float = SHOWN_ZERO) -> list:
    """A column of numbers with 6 significant digits, each below ``relative`` x the column's largest
    magnitude (or below ``absolute``) written as 0: round-off is not a value (1.6e-15 deg is 0)."""
    big = max((abs(v) for v in values if v == v), default=0.0)
    tiny = max(absolute, relative * big)
    return [f"{shown(v, tiny):.6g}" for v in values]


@dataclass(frozen=True)
class RateUnits:
    """The units a table writes rates and accelerations in: SI unless a person typed others with
    ``--rate``/``--accel`` (:meth:`typed`).  Values stay SI everywhere else (JSON, analysis)."""

    angular_rate: str = "rad/s"
    angular_acceleration: str = "rad/s^2"
    linear_rate: str = "m/s"
    linear_acceleration: str = "m/s^2"

    #: a unit typed -> (field, display unit): an angle or a length given for a rate keeps its old meaning
    #: (--rate crank=90deg is 90 deg/s); degrees typed for a rate show accelerations in deg/s^2 too
    #: (each rate's acceleration is its unit per second: rpm -> rpm/s, never rpm beside rad/s^2)
    _RATE = {"deg": ("deg/s", "deg/s^2"), "deg/s": ("deg/s", "deg/s^2"), "rpm": ("rpm", "rpm/s"),
             "rev/min": ("rpm", "rpm/s"), "rev/s": ("rev/s", "rev/s^2"), "mm": ("mm/s", "mm/s^2"),
             "mm/s": ("mm/s", "mm/s^2"), "cm": ("cm/s", "cm/s^2"), "cm/s": ("cm/s", "cm/s^2")}
    _ACCEL = {"deg": "deg/s^2", "deg/s^2": "deg/s^2", "deg/s2": "deg/s^2", "mm": "mm/s^2", "mm/s^2": "mm/s^2",
              "mm/s2": "mm/s^2", "rpm/s": "rpm/s", "rev/s^2": "rev/s^2", "rev/s2": "rev/s^2", "cm/s^2": "cm/s^2",
              "cm/s2": "cm/s^2"}

    @classmethod
    def typed(cls, rate_units=(), accel_units=()) -> "RateUnits":
        """The units of the first rate and acceleration typed of each kind (angular, linear); SI for
        the kinds typed bare or in SI."""
        out = {}
        for unit in rate_units:
            written = cls._RATE.get(unit) or cls._RATE.get(unit.lower())
            kind = unit_kind(unit)
            if written is None or kind is None:
                continue
            linear = kind in ("length", "linear rate")
            out.setdefault("linear_rate" if linear else "angular_rate", written[0])
            if written[1]:
                out.setdefault("linear_acceleration" if linear else "angular_acceleration", written[1])
        for unit in accel_units:
            written, kind = cls._ACCEL.get(unit) or cls._ACCEL.get(unit.lower()), unit_kind(unit)
            if written and kind:
                key = "linear_acceleration" if kind in ("length", "linear acceleration") else "angular_acceleration"
                out[key] = written  # an acceleration typed wins over one implied by a rate
        return cls(**out)

    def rate(self, linear: bool) -> str:
        return self.linear_rate if linear else self.angular_rate

    def acceleration(self, linear: bool) -> str:
        return self.linear_acceleration if linear else self.angular_acceleration

    @staticmethod
    def of(value: float, unit: str) -> float:
        """An SI value in ``unit`` (rad/s -> rpm ...): units.in_unit."""
        return in_unit(value, unit)


def input_rate_words(name: str, rate: float, unit: str | None, linear: bool) -> str:
    """What a sweep's rates and accelerations are for, in words: ``at crank 120 rpm`` for a rate typed
    (``unit`` as typed; an angle or a length typed for a rate is per second), ``per 1 rad/s of crank`` for
    the default (the input at 1 rad/s or 1 m/s: the rates are then the velocity ratios)."""
    si = "m/s" if linear else "rad/s"
    if not unit:
        return f"per {rate:g} {si} of {name}" if rate == 1.0 else f"at {name} {rate:g} {si}"
    written = RateUnits._RATE.get(unit, (None,))[0] or RateUnits._RATE.get(unit.lower(), (None,))[0] or unit
    return f"at {name} {in_unit(rate, written.replace('^', '')):.6g} {written}"


#: What a spreadsheet reads as the start of a formula in a text cell (CSV injection).
_FORMULA = ("=", "+", "-", "@", "\t", "\r")


def csv_cell(value):
    """A cell for a CSV written from untrusted names: numbers as they are, but a value that does not
    exist (NaN: an effort redundant actuation leaves undetermined) empty, as a missing one (None); a
    text that a spreadsheet would run as a formula (=, +, -, @, tab, CR first) gets a leading apostrophe."""
    if isinstance(value, float) and value != value:
        return ""
    if isinstance(value, str) and value.startswith(_FORMULA):
        try:
            float(value)
        except ValueError:
            return "'" + value
    return value


def csv_text(header, rows) -> str:
    """CSV text (csv.writer: names with commas, quotes or newlines are quoted) with every cell through
    :func:`csv_cell`; one line per row."""
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    w.writerow([csv_cell(h) for h in header])
    for row in rows:
        w.writerow([csv_cell(c) for c in row])
    return out.getvalue()

"""Plain-text tables and number formatting shared by every text report."""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass

from ..units import Quantity, shown_unit, unit_text
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np
    from collections.abc import Iterator

__all__ = ["table", "shown", "shown_text", "fmt_vec", "column_text", "csv_cell", "csv_text", "SHOWN_ZERO", "RateUnits",
           "input_rate_words"]

#: Display cut-off: a number smaller than this in magnitude is written as 0 (round-off is not a value).
SHOWN_ZERO = 1e-12


def table(headers: list, rows: list) -> str:
    """A plain-text table with aligned columns."""
    rows = [[str(c) for c in r] for r in rows]
    widths = [max(len(str(h)), *(len(r[i]) for r in rows)) if rows else len(str(h)) for i, h in enumerate(headers)]
    line = "  ".join(str(h).ljust(w) for h, w in zip(headers, widths)).rstrip()
    out = [line, "  ".join("-" * w for w in widths)]
    out += ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
    return "\n".join(out)


def shown(x: float, below: float = SHOWN_ZERO) -> float:
    """x as written: 0.0 where its magnitude is below ``below``, and never -0.0."""
    return (0.0 if abs(x) < below else x) + 0.0


def shown_text(x: float | None, digits: int = 6, below: float = SHOWN_ZERO, missing: str = "?") -> str:
    """A number as every text table writes it: ``digits`` significant digits, round-off below ``below``
    as 0 (``shown``); ``missing`` for None."""
    return missing if x is None else f"{shown(x, below):.{digits}g}"


def fmt_vec(v: np.ndarray | tuple, width: int = 11) -> str:
    """Numbers with 6 significant digits; round-off below SHOWN_ZERO shows as 0."""
    return " ".join(f"{shown(x):>{width}.6g}" for x in v)


def column_text(values: np.ndarray | list, relative: float = 1e-9, absolute: float = SHOWN_ZERO) -> list:
    """A column of numbers with 6 significant digits, each below ``relative`` x the column's largest
    magnitude (or below ``absolute``) written as 0: round-off is not a value (1.6e-15 deg is 0)."""
    big = max((abs(v) for v in values if v == v), default=0.0)
    tiny = max(absolute, relative * big)
    return [f"{shown(v, tiny):.6g}" for v in values]


@dataclass(frozen=True)
class RateUnits:
    """The units a table writes rates and accelerations in: SI unless a person typed others with
    ``--rate``/``--accel`` (:meth:`typed`).  Values stay SI everywhere else (JSON, analysis); which
    unit a typed one makes is units.shown_unit's rule, the conversion units.in_unit."""

    angular_rate: str = "rad/s"
    angular_acceleration: str = "rad/s^2"
    linear_rate: str = "m/s"
    linear_acceleration: str = "m/s^2"

    @classmethod
    def typed(cls, rates=(), accels=()) -> RateUnits:
        """The units of the first rate and acceleration typed of each kind (angular, linear), from the
        units.Quantity values of --rate and --accel: a rate's unit per second for the accelerations
        too (rpm: rpm/s), an acceleration typed winning over it; SI for the kinds typed bare or in SI."""
        out = [{}, {}]  # implied by a rate, typed as an acceleration
        for quantities, fields, into in ((rates, ("rate", "acceleration"), out[0]),
                                         (accels, ("acceleration",), out[1])):
            for q in quantities:
                side = "linear" if q.kind in ("length", "linear rate", "linear acceleration") else "angular"
                for field in fields:
                    kind = f"{side} {field}"
                    unit = shown_unit(q.unit, kind)
                    if q.unit and unit != shown_unit("", kind):
                        into.setdefault(kind.replace(" ", "_"), unit)
        return cls(**{**out[0], **out[1]})

    def rate(self, linear: bool) -> str:
        return self.linear_rate if linear else self.angular_rate

    def acceleration(self, linear: bool) -> str:
        return self.linear_acceleration if linear else self.angular_acceleration


def input_rate_words(name: str, rate: Quantity | None, linear: bool) -> str:
    """What a sweep's rates and accelerations are for, in words: ``at crank 120 rpm`` for a rate typed
    (shown in its unit; an angle or a length typed for a rate is per second), ``per 1 rad/s of crank``
    for the default (the input at 1 rad/s or 1 m/s: the rates are then the velocity ratios)."""
    si = "m/s" if linear else "rad/s"
    value = 1.0 if rate is None else rate.value
    if rate is None or not rate.unit:
        return f"per {value:g} {si} of {name}" if value == 1.0 else f"at {name} {value:g} {si}"
    return f"at {name} {unit_text(value, shown_unit(rate.unit, 'linear rate' if linear else 'angular rate'))}"


#: What a spreadsheet reads as the start of a formula in a text cell (CSV injection).
_FORMULA = ("=", "+", "-", "@", "\t", "\r")


def csv_cell(value: str) -> str:
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


def csv_text(header: list, rows: Iterator | list) -> str:
    """CSV text (csv.writer: names with commas, quotes or newlines are quoted) with every cell through
    :func:`csv_cell`; one line per row."""
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    w.writerow([csv_cell(h) for h in header])
    for row in rows:
        w.writerow([csv_cell(c) for c in row])
    return out.getvalue()

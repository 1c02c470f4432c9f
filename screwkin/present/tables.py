"""Plain-text tables and number formatting shared by every text report."""

from __future__ import annotations

import csv
import io

__all__ = ["table", "shown", "fmt_vec", "column_text", "csv_cell", "csv_text", "SHOWN_ZERO"]

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


def column_text(values, relative: float = 1e-9, absolute: float = 1e-12) -> list:
    """A column of numbers with 6 significant digits, each below ``relative`` x the column's largest
    magnitude (or below ``absolute``) written as 0: round-off is not a value (1.6e-15 deg is 0)."""
    big = max((abs(v) for v in values if v == v), default=0.0)
    tiny = max(absolute, relative * big)
    return [f"{(0.0 if abs(v) < tiny else v) + 0.0:.6g}" for v in values]


#: What a spreadsheet reads as the start of a formula in a text cell (CSV injection).
_FORMULA = ("=", "+", "-", "@", "\t", "\r")


def csv_cell(value):
    """A cell for a CSV written from untrusted names: numbers as they are; a text that a spreadsheet
    would run as a formula (=, +, -, @, tab, CR first) gets a leading apostrophe."""
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

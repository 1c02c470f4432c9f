"""CSV written the one way: every CSV screwkin writes (sweep, scan, map, workspace, study)
goes through :func:`csv_text` or :func:`write_csv`.

``csv.writer`` quotes a cell holding a comma, a quote or a line break, so a link or joint
name cannot shift the columns; a text cell that a spreadsheet would run as a formula
(first character ``=``, ``+``, ``-``, ``@``, tab or carriage return, OWASP's list) gets
a leading ``'``.  A cell that reads as a number (``-0.5``, ``-inf``) is a number, not a
formula, and is written as it is.
"""

from __future__ import annotations

import csv
import io

__all__ = ["safe_cell", "csv_text", "write_csv"]

_FORMULA = ("=", "+", "-", "@", "\t", "\r")


def safe_cell(v):
    """``v`` as a CSV cell: a text that is not a number and starts like a formula gets a leading ``'``."""
    if not isinstance(v, str) or not v.startswith(_FORMULA):
        return v
    try:
        float(v)
        return v
    except ValueError:
        return "'" + v


def _write(f, rows) -> None:
    w = csv.writer(f, lineterminator="\n")
    for row in rows:
        w.writerow([safe_cell(c) for c in row])


def csv_text(rows) -> str:
    """The rows (sequences of cells; the first is the header) as CSV text."""
    out = io.StringIO()
    _write(out, rows)
    return out.getvalue()


def write_csv(path, rows) -> None:
    """The rows written as CSV to the file ``path``."""
    with open(path, "w", newline="") as f:
        _write(f, rows)

"""JSON as screwkin writes it: numpy values as plain numbers and lists; an infinite number as the
string "inf" or "-inf" (JSON has no Infinity); a NaN refused as the bug it is (a value that does not
exist is None, written so by the analysis that knows why); and the indented text of json.dumps
written fast for the long lists of numbers a sweep holds.
"""

from __future__ import annotations

import json
import math
from itertools import chain

import numpy as np

__all__ = ["to_jsonable", "nan_to_none", "json_text", "json_of"]


def to_jsonable(obj, _where: str = ""):
    """Plain Python for json.dumps: numpy values as numbers and lists; an infinite number (the
    condition number of a singular matrix, an unbounded effort) as the string "inf" or "-inf",
    since JSON has no Infinity.  A NaN is a bug, never an answer: RuntimeError naming where it
    sits (a value that does not exist -- a map cell off the branch -- is None, written so by
    the analysis that knows why)."""
    if isinstance(obj, dict):
        return {k: to_jsonable(v, f"{_where}.{k}") for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        if isinstance(obj, list) and (_numbers(obj) or _rows(obj)):  # finite floats only: nothing to convert
            return obj
        return [to_jsonable(v, f"{_where}[{i}]") for i, v in enumerate(obj)]
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind == "f" and np.isfinite(obj).all():  # (a sweep's arrays: one C call, not a call a number)
            return obj.tolist()
        return to_jsonable(obj.tolist(), _where)
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not np.isfinite(obj):
        if np.isnan(obj):
            raise RuntimeError(f"internal error: NaN in the JSON output at {_where.lstrip('.') or 'the top'}")
        return "inf" if obj > 0 else "-inf"
    return obj


def nan_to_none(a) -> list:
    """An array whose NaN entries mean 'no value here' (said so by its analysis) as nested lists
    with None there, for to_jsonable."""
    a = np.asarray(a, float)
    return np.where(np.isnan(a), None, a.astype(object)).tolist()


def json_text(obj, indent: int = 2, _level: int = 0) -> str:
    """json.dumps(obj, indent=indent) of to_jsonable's output, character for character, with the
    lists of numbers (a sweep's tens of thousands of values) written in one join each instead of
    json's pure-Python encoder (the one it uses with indent), which takes seconds on them."""
    pad, inner = " " * (indent * _level), " " * (indent * (_level + 1))
    if isinstance(obj, dict) and all(isinstance(k, str) for k in obj):
        if not obj:
            return "{}"
        items = (f"{inner}{json.dumps(k)}: {json_text(v, indent, _level + 1)}" for k, v in obj.items())
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(obj, (list, tuple)):
        if not obj:
            return "[]"
        if _numbers(obj):
            return "[\n" + inner + (",\n" + inner).join(map(float.__repr__, obj)) + "\n" + pad + "]"
        width = _rows(obj)
        if width:  # rows of numbers of one length (vectors along a sweep): one join over all the numbers
            return _rows_text(map(float.__repr__, chain.from_iterable(obj)), len(obj), width, pad, inner, " " * indent)
        if all(isinstance(v, list) and v and _numbers(v) for v in obj):  # rows of numbers (vectors along a sweep)
            deeper = inner + " " * indent
            sep = ",\n" + deeper
            rows = ("[\n" + deeper + sep.join(map(float.__repr__, v)) + "\n" + inner + "]" for v in obj)
            return "[\n" + inner + (",\n" + inner).join(rows) + "\n" + pad + "]"
        return "[\n" + ",\n".join(inner + json_text(v, indent, _level + 1) for v in obj) + "\n" + pad + "]"
    return json.dumps(obj, indent=indent).replace("\n", "\n" + pad)


def json_of(obj, indent: int = 2, _level: int = 0, _where: str = "") -> str:
    """json_text(to_jsonable(obj)), the same text, with the finite float arrays (a sweep's stacks,
    (N,) or (N, k)) written from their values: no list a row, no check a number in Python."""
    if isinstance(obj, dict) and all(isinstance(k, str) for k in obj) and obj:
        pad, inner = " " * (indent * _level), " " * (indent * (_level + 1))
        items = (f"{inner}{json.dumps(k)}: {json_of(v, indent, _level + 1, f'{_where}.{k}')}" for k, v in obj.items())
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if (isinstance(obj, np.ndarray) and obj.dtype.kind == "f" and obj.ndim in (1, 2) and obj.size
            and np.isfinite(obj).all()):
        pad, inner = " " * (indent * _level), " " * (indent * (_level + 1))
        values = map(float.__repr__, obj.ravel().tolist())
        if obj.ndim == 1:
            return "[\n" + inner + (",\n" + inner).join(values) + "\n" + pad + "]"
        return _rows_text(values, *obj.shape, pad, inner, " " * indent)
    return json_text(to_jsonable(obj, _where), indent, _level)


def _rows_text(values, n: int, width: int, pad: str, inner: str, step: str) -> str:
    """json.dumps' indented text of n rows of ``width`` numbers, ``values`` their texts row by row."""
    deeper = inner + step
    parts = [""] * (2 * n * width - 1)
    parts[::2] = values
    parts[1::2] = ([",\n" + deeper] * (width - 1) + ["\n" + inner + "],\n" + inner + "[\n" + deeper]) * (n - 1) + [
        ",\n" + deeper] * (width - 1)
    return "[\n" + inner + "[\n" + deeper + "".join(parts) + "\n" + inner + "]\n" + pad + "]"


def _numbers(values) -> bool:
    """A list of finite floats only (two loops in C)."""
    return set(map(type, values)) == {float} and all(map(math.isfinite, values))


def _rows(values) -> int:
    """The length of every row when ``values`` is a list of lists of finite floats, all of one
    nonzero length (a sweep's vectors); else 0 (loops in C, no Python call a row)."""
    if not values or set(map(type, values)) != {list}:
        return 0
    widths = set(map(len, values))
    if len(widths) != 1 or 0 in widths or not _numbers(list(chain.from_iterable(values))):
        return 0
    return widths.pop()

"""JSON as screwkin writes it: the one writer of every ``--json``, of ``report``'s data.json and of
the Python API's ``to_dict``.

The rule (README, "Command line"): numbers in SI; numpy values as plain numbers and lists; an
infinite number as the string ``"inf"`` or ``"-inf"`` (JSON has no Infinity: a force ellipsoid's
semi-axis along a wrench that loads no input, a pure translation's pitch); a value that does not
exist -- NaN inside screwkin: a map cell off the branch, an effort redundant actuation leaves
undetermined -- as ``null``, as None is.  The indented text of json.dumps is written fast for the
long lists of numbers a sweep holds.
"""

from __future__ import annotations

import json
import math
from itertools import chain

import numpy as np

__all__ = ["to_jsonable", "json_of", "json_text"]


def to_jsonable(obj):
    """Plain Python for json.dumps by the rule above: numpy values as numbers and lists, an infinite
    number as "inf" or "-inf", a NaN as None."""
    if isinstance(obj, dict):
        return {k: to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        if isinstance(obj, list) and (_numbers(obj) or _rows(obj)):  # finite floats only: nothing to convert
            return obj
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind == "f" and np.isfinite(obj).all():  # (a sweep's arrays: one C call, not a call a number)
            return obj.tolist()
        return to_jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        if math.isnan(obj):
            return None
        return "inf" if obj > 0 else "-inf"
    return obj


def json_of(obj, indent: int | None = 2, sort_keys: bool = False) -> str:
    """The JSON text of ``obj`` by the rule of this module: json.dumps(to_jsonable(obj), indent=indent,
    sort_keys=sort_keys), character for character (``indent=None``: on one line), with the finite float
    arrays (a sweep's stacks, (N,) or (N, k)) written from their values: no list a row, no check a
    number in Python."""
    if indent is None:
        return json.dumps(to_jsonable(obj), sort_keys=sort_keys, allow_nan=False)
    return _of(obj, indent, sort_keys, 0)


def _of(obj: np.ndarray, indent: int, sort_keys: bool, level: int) -> str:
    if isinstance(obj, dict) and all(isinstance(k, str) for k in obj) and obj:
        pad, inner = " " * (indent * level), " " * (indent * (level + 1))
        items = (f"{inner}{json.dumps(k)}: {_of(v, indent, sort_keys, level + 1)}" for k, v in _items(obj, sort_keys))
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if (isinstance(obj, np.ndarray) and obj.dtype.kind == "f" and obj.ndim in (1, 2) and obj.size
            and np.isfinite(obj).all()):
        pad, inner = " " * (indent * level), " " * (indent * (level + 1))
        values = map(float.__repr__, obj.ravel().tolist())
        if obj.ndim == 1:
            return "[\n" + inner + (",\n" + inner).join(values) + "\n" + pad + "]"
        return _rows_text(values, *obj.shape, pad, inner, " " * indent)
    if isinstance(obj, np.ndarray) and obj.ndim in (1, 2) and obj.size:
        values = _texts(obj)
        if values is not None:  # (a map's grids: NaN cells, flags, kinds -- a join, not a dumps a value)
            pad, inner = " " * (indent * level), " " * (indent * (level + 1))
            if obj.ndim == 1:
                return "[\n" + inner + (",\n" + inner).join(values) + "\n" + pad + "]"
            return _rows_text(values, *obj.shape, pad, inner, " " * indent)
    return json_text(to_jsonable(obj), indent, sort_keys, level)


def _texts(obj: np.ndarray) -> list | None:
    """The JSON texts of an array's values (row by row) when they are all NaN-or-finite floats, booleans or
    strings; else None."""
    flat = obj.ravel()
    if obj.dtype.kind == "f" and not np.isinf(flat).any():
        return ["null" if v != v else float.__repr__(v) for v in flat.tolist()]
    if obj.dtype.kind == "b":
        return ["true" if v else "false" for v in flat.tolist()]
    values = flat.tolist()
    if obj.dtype.kind in "OU" and all(type(v) is str for v in values):
        return [json.dumps(v) for v in values]
    return None


def _items(d: dict, sort_keys: bool):
    return sorted(d.items(), key=lambda kv: kv[0]) if sort_keys else d.items()


def json_text(obj, indent: int = 2, sort_keys: bool = False, _level: int = 0) -> str:
    """json.dumps(obj, indent=indent, sort_keys=sort_keys) of to_jsonable's output, character for
    character, with the lists of numbers (a sweep's tens of thousands of values) written in one join
    each instead of json's pure-Python encoder (the one it uses with indent), which takes seconds on them."""
    pad, inner = " " * (indent * _level), " " * (indent * (_level + 1))
    if isinstance(obj, dict) and all(isinstance(k, str) for k in obj):
        if not obj:
            return "{}"
        items = (f"{inner}{json.dumps(k)}: {json_text(v, indent, sort_keys, _level + 1)}"
                 for k, v in _items(obj, sort_keys))
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
        return "[\n" + ",\n".join(inner + json_text(v, indent, sort_keys, _level + 1) for v in obj) + "\n" + pad + "]"
    # (allow_nan=False: to_jsonable left no NaN or infinity; one would be a bug in this module)
    return json.dumps(obj, indent=indent, sort_keys=sort_keys, allow_nan=False).replace("\n", "\n" + pad)


def _rows_text(values, n: int, width: int, pad: str, inner: str, step: str) -> str:
    """json.dumps' indented text of n rows of ``width`` numbers, ``values`` their texts row by row."""
    deeper = inner + step
    parts = [""] * (2 * n * width - 1)
    parts[::2] = values
    parts[1::2] = ([",\n" + deeper] * (width - 1) + ["\n" + inner + "],\n" + inner + "[\n" + deeper]) * (n - 1) + [
        ",\n" + deeper] * (width - 1)
    return "[\n" + inner + "[\n" + deeper + "".join(parts) + "\n" + inner + "]\n" + pad + "]"


def _numbers(values: list) -> bool:
    """A list of finite floats only (two loops in C)."""
    return set(map(type, values)) == {float} and all(map(math.isfinite, values))


def _rows(values: list) -> int:
    """The length of every row when ``values`` is a list of lists of finite floats, all of one
    nonzero length (a sweep's vectors); else 0 (loops in C, no Python call a row)."""
    if not values or set(map(type, values)) != {list}:
        return 0
    widths = set(map(len, values))
    if len(widths) != 1 or 0 in widths or not _numbers(list(chain.from_iterable(values))):
        return 0
    return widths.pop()

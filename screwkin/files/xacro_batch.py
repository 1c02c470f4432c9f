"""A xacro family expanded once for many designs (a study's chunk), by the same expansion as
:func:`screwkin.files.xacro.expand`, with the parameters' values carried as arrays.

Each varied argument reaches the file as a token (``skwbatch0x``, a name no file writes) bound to
:class:`Batch`, one value per design; the interpreter of ``${...}`` computes with Batch values as
with numbers (numpy, element by element: the functions of :data:`.xacro_eval.FUNCTIONS` as numpy's,
``a if c else b`` as ``where``, ``and``/``or`` as Python's, value by value), and a Batch written into
the file becomes a token again.  The text that comes out is the family's template: each design's
URDF is it with every token replaced by that design's value (``repr`` of the float, as
``design_args`` writes an argument and xacro a computed float; an integer xacro would write as ``3``
comes out as ``3.0``, the same number).

Where the structure of the file would depend on a parameter -- a ``xacro:if`` or ``xacro:unless``
that some designs take and others do not, a parameter inside quotes (``'$(arg a)' == '0.1'``),
text joined to one, a token in a name, a type, a joint's limits or anything but a number of a
placement, an axis, an inertial or a geometry -- :class:`Unbatchable` says so and the caller
expands the designs one by one.  Where one design's expansion would fail (a math domain error, a
division by zero, an overflow: its value is not finite) it is marked in ``bad``, for the caller to
expand alone (the error is then xacro's own).
"""

from __future__ import annotations

import ast
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import MechanismFileError, UsageError
from .description import MechanismSpec
from .urdf import read_urdf
from .xacro import expand
from .xacro_eval import COMPARE, FUNCTIONS, Interpreter, Refused, call_function, evaluate, function_name, power
from .xmlsafe import parse_xml_text
from typing import TYPE_CHECKING, NoReturn

if TYPE_CHECKING:
    from typing import Any
    from collections.abc import Callable

__all__ = ["Batch", "BatchExpansion", "Unbatchable", "expand_batch", "read_designs"]

TOKEN = re.compile(r"skwbatch([0-9]+)x")
#: (element, attribute) pairs a parameter may reach: numbers of placements, axes, inertials, geometry, colour.
ALLOWED = {("origin", "xyz"), ("origin", "rpy"), ("axis", "xyz"), ("link1", "xyz"), ("link1", "rpy"),
           ("link2", "xyz"), ("link2", "rpy"), ("mass", "value"), ("box", "size"), ("cylinder", "radius"),
           ("cylinder", "length"), ("sphere", "radius"), ("capsule", "radius"), ("capsule", "length"),
           ("color", "rgba")} | {("inertia", k) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
_NUMPY = {"sin": np.sin, "cos": np.cos, "tan": np.tan, "asin": np.arcsin, "acos": np.arccos, "atan": np.arctan,
          "atan2": np.arctan2, "sqrt": np.sqrt, "radians": np.radians, "degrees": np.degrees, "exp": np.exp,
          "log": np.log, "floor": np.floor, "ceil": np.ceil, "abs": np.abs}
assert set(_NUMPY) | {"min", "max", "pow"} == set(FUNCTIONS)


class Unbatchable(Exception):
    """The family cannot be expanded for its designs at once (the reason): expand them one by one."""


class _Context:
    """The Batch values of one expansion, each written into the text as its token."""

    def __init__(self, n: int) -> None:
        self.n = n
        self.batches = []
        self._ids = {}
        self.bad = np.zeros(n, bool)
        self.reason = None

    def refuse(self, why: str) -> NoReturn:
        self.reason = self.reason or why
        raise Unbatchable(why)

    def token(self, b: Batch) -> str:
        k = self._ids.get(id(b))
        if k is None:
            k = self._ids[id(b)] = len(self.batches)
            self.batches.append(b)
        return f"skwbatch{k}x"

    def lookup(self, name: str):
        m = TOKEN.fullmatch(name.strip()) if isinstance(name, str) else None
        return self.batches[int(m.group(1))] if m and int(m.group(1)) < len(self.batches) else None


def _finite_bad(values: np.ndarray, bad: np.ndarray):
    if values.dtype == bool:
        return bad
    return bad | ~np.isfinite(values)


class Batch:
    """One number per design (``v``) and the designs whose scalar expansion would have failed on the
    way to it (``bad``: a math domain error, a division by zero, an overflow)."""

    __slots__ = ("v", "bad", "ctx")

    def __init__(self, v: float | np.ndarray, bad: np.ndarray, ctx: _Context) -> None:
        self.v, self.bad, self.ctx = np.asarray(v), bad, ctx

    def _other(self, o: Batch) -> tuple:
        if isinstance(o, Batch):
            return o.v, o.bad
        if isinstance(o, (bool, int, float)):
            return o, False
        self.ctx.refuse("a parameter combined with text")

    def _bin(self, o: object, f: Callable[..., np.ndarray], reverse: bool=False) -> Batch:
        ov, ob = self._other(o)
        with np.errstate(all="ignore"):
            r = np.asarray(f(ov, self.v) if reverse else f(self.v, ov))
        return Batch(r, _finite_bad(r, self.bad | ob), self.ctx)

    def __add__(self, o: object) -> Batch: return self._bin(o, np.add)
    def __radd__(self, o: object) -> Batch: return self._bin(o, np.add, True)
    def __sub__(self, o: object) -> Batch: return self._bin(o, np.subtract)
    def __rsub__(self, o: object) -> Batch: return self._bin(o, np.subtract, True)
    def __mul__(self, o: object) -> Batch: return self._bin(o, np.multiply)
    def __rmul__(self, o: object) -> Batch: return self._bin(o, np.multiply, True)
    def __truediv__(self, o: object) -> Batch: return self._bin(o, np.true_divide)
    def __rtruediv__(self, o: object) -> Batch: return self._bin(o, np.true_divide, True)
    def __floordiv__(self, o: object) -> Batch: return self._bin(o, np.floor_divide)
    def __rfloordiv__(self, o: object) -> Batch: return self._bin(o, np.floor_divide, True)
    def __mod__(self, o: object) -> Batch: return self._bin(o, np.mod)
    def __rmod__(self, o: object) -> Batch: return self._bin(o, np.mod, True)
    def __lt__(self, o: object) -> Batch: return self._bin(o, np.less)
    def __le__(self, o: object) -> Batch: return self._bin(o, np.less_equal)
    def __gt__(self, o: object) -> Batch: return self._bin(o, np.greater)
    def __ge__(self, o: object) -> Batch: return self._bin(o, np.greater_equal)
    def __eq__(self, o: object) -> Batch: return self._bin(o, np.equal)
    def __ne__(self, o: object) -> Batch: return self._bin(o, np.not_equal)
    __hash__ = object.__hash__

    def __neg__(self) -> Batch:
        return Batch(-self.v, self.bad, self.ctx)

    def __pos__(self) -> Batch:
        return self

    def __bool__(self) -> bool:
        good = np.asarray(self.v, bool)[~self.bad]
        if good.all():
            return True
        if not good.any():
            return False
        self.ctx.refuse("a condition on a parameter that some designs meet and others do not (the file's "
                        "structure depends on it)")

    def __str__(self) -> str:  # written into the file: a token, replaced by each design's value
        return self.ctx.token(self)

    __repr__ = __str__

    def _refuse_number(self, *_: Any) -> None:
        self.ctx.refuse("a parameter used where xacro needs one number")

    __int__ = __float__ = __index__ = _refuse_number


def _truth(x: object) -> bool | np.ndarray:
    return np.asarray(x.v, bool) if isinstance(x, Batch) else bool(x)


class _BatchInterpreter(Interpreter):
    """xacro_eval's interpreter with Batch values: what it does with a number, it does with each
    design's number."""

    def __init__(self, symbols: dict, ctx: _Context) -> None:
        super().__init__(symbols)
        self.ctx = ctx

    def _where(self, test: Batch, a: object, b: object) -> Batch:
        """``a if test else b``, design by design (each design's failures from its own branch and the test)."""
        ctx = self.ctx
        t = np.asarray(test.v, bool) if isinstance(test, Batch) else np.full(ctx.n, bool(test))
        vals = []
        for x in (a, b):
            if isinstance(x, str):
                ctx.refuse("text chosen by a condition on a parameter")
            vals.append((x.v, x.bad) if isinstance(x, Batch) else (x, np.zeros(ctx.n, bool)))
        (av, ab), (bv, bb) = vals
        tb = test.bad if isinstance(test, Batch) else False
        return Batch(np.where(t, av, bv), np.where(t, ab, bb) | tb, ctx)

    def value(self, node: ast.AST):
        ctx = self.ctx
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and TOKEN.search(node.value):
            ctx.refuse("a parameter inside quotes (compared or joined as text)")
        if isinstance(node, ast.Name):
            b = ctx.lookup(node.id)
            if b is not None:
                return b
            v = self.symbols[node.id] if node.id in self.symbols else None
            if isinstance(v, Batch):
                return v
            if isinstance(v, str) and ctx.lookup(v) is not None:  # a property holding an argument's token
                return ctx.lookup(v)
            return super().value(node)
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Pow):
            a, b = self.value(node.left), self.value(node.right)
            if isinstance(a, Batch) or isinstance(b, Batch):
                return a._bin(b, np.power) if isinstance(a, Batch) else b._bin(a, np.power, True)
            return power(a, b)
        if isinstance(node, ast.Call):
            name = function_name(node.func)
            args = [self.value(a) for a in node.args]
            if not any(isinstance(a, Batch) for a in args):
                return call_function(name, args)
            if any(isinstance(a, str) for a in args):
                raise Refused(f"{name}() of text")
            vals = [(a.v, a.bad) if isinstance(a, Batch) else (a, False) for a in args]
            bad = np.logical_or.reduce([np.broadcast_to(b, (ctx.n,)) for _, b in vals])
            with np.errstate(all="ignore"):
                if name in ("min", "max"):
                    if not args:
                        raise TypeError(f"{name}() needs at least one argument")
                    r = (np.minimum if name == "min" else np.maximum).reduce(np.broadcast_arrays(*(v for v, _ in vals)))
                elif name == "pow":
                    if len(args) != 2:
                        raise TypeError("pow() takes two arguments")
                    r = np.power(np.asarray(vals[0][0], float), vals[1][0])
                else:
                    r = _NUMPY[name](*(v for v, _ in vals))
            r = np.asarray(r)
            return Batch(r, _finite_bad(r, bad), ctx)
        if isinstance(node, ast.IfExp):
            test = self.value(node.test)
            if not isinstance(test, Batch):
                return self.value(node.body) if test else self.value(node.orelse)
            return self._where(test, self.value(node.body), self.value(node.orelse))
        if isinstance(node, ast.BoolOp):  # Python's: the first value that decides, design by design
            values = [self.value(item) for item in node.values]
            if not any(isinstance(v, Batch) for v in values):
                return super().value(node)
            and_ = isinstance(node.op, ast.And)
            out = values[-1]
            for v in reversed(values[:-1]):
                test = Batch(np.asarray(v.v, bool), v.bad, ctx) if isinstance(v, Batch) else bool(v)
                out = self._where(test, out, v) if and_ else self._where(test, v, out)
            return out
        if isinstance(node, ast.Compare):
            left = self.value(node.left)
            results = []
            for op, right_node in zip(node.ops, node.comparators):
                right = self.value(right_node)
                if (isinstance(left, Batch) or isinstance(right, Batch)) and (isinstance(left, str)
                                                                               or isinstance(right, str)):
                    ctx.refuse("a parameter compared with text")
                r = COMPARE[type(op)](left, right)
                if not isinstance(r, Batch) and not r:
                    return False
                results.append(r)
                left = right
            batches = [r for r in results if isinstance(r, Batch)]
            if not batches:
                return True
            return Batch(np.logical_and.reduce([np.asarray(r.v, bool) for r in batches]),
                         np.logical_or.reduce([r.bad for r in batches]), ctx)
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not):
            v = self.value(node.operand)
            if isinstance(v, Batch):
                return Batch(~np.asarray(v.v, bool), v.bad, ctx)
            return not v
        return super().value(node)


def _evaluator(ctx: _Context):
    def batch_evaluate(expr, symbols=None):
        v = evaluate(expr, symbols, lambda table: _BatchInterpreter(table, ctx))
        if isinstance(v, Batch):  # where this expression fails design by design, that design fails
            ctx.bad |= v.bad
        return v

    return batch_evaluate


@dataclass(frozen=True)
class BatchExpansion:
    """The family's template: ``parts`` (text) alternating with ``slots`` (an index into ``values``, one
    per token written), ``values`` (an array of one value per design for each token), and ``bad``: the
    designs whose own expansion fails (expand them alone for xacro's message)."""

    parts: tuple
    slots: tuple
    values: tuple
    bad: np.ndarray

    def design(self, k: int) -> str:
        """Design k's URDF text."""
        out = [self.parts[0]]
        for slot, part in zip(self.slots, self.parts[1:]):
            v = self.values[slot]
            out.append(str(bool(v[k])) if v.dtype == bool else repr(float(v[k])))
            out.append(part)
        return "".join(out)


def _check_places(text: str, path: str | Path) -> None:
    """Tokens only in the numbers of ALLOWED attributes (anything else: the structure may change)."""
    root = parse_xml_text(text, path)
    for elem in root.iter():
        tag = elem.tag.rsplit("}", 1)[-1] if isinstance(elem.tag, str) else ""
        if TOKEN.search(tag) or TOKEN.search(elem.text or "") or TOKEN.search(elem.tail or ""):
            raise Unbatchable(f"a parameter reaches the text or the name of <{tag}>")
        for key, value in elem.attrib.items():
            if TOKEN.search(key) or (TOKEN.search(value) and (tag, key) not in ALLOWED):
                raise Unbatchable(f"a parameter reaches <{tag} {key}=...> (only placements, axes, inertials and "
                                  "geometry sizes may vary for the family to be expanded once)")


def expand_batch(path: str | Path, text: str, args: dict, parameters: dict) -> BatchExpansion:
    """The template of xacro file ``path`` with the fixed ``args`` (as for expand) and the varied
    ``parameters`` ({name: array of SI values, one per design}); Unbatchable when the family cannot
    be expanded at once (the reason)."""
    names = list(parameters)
    values = [np.asarray(parameters[n], float) for n in names]
    n = len(values[0]) if values else 0
    ctx = _Context(n)
    for v in values:
        ctx.token(Batch(v, ~np.isfinite(v), ctx))
    given = dict(args)
    given.update({name: f"skwbatch{k}x" for k, name in enumerate(names)})
    try:
        out = expand(path, text, given, evaluator=_evaluator(ctx))
    except (MechanismFileError, UsageError, RecursionError) as exc:
        raise Unbatchable(ctx.reason or f"expanding the designs at once failed ({str(exc)[-160:]})") from None
    if ctx.reason:  # refused inside something that did not let the exception through
        raise Unbatchable(ctx.reason)
    _check_places(out, path)
    pieces = TOKEN.split(out)
    parts, slots = tuple(pieces[0::2]), tuple(int(k) for k in pieces[1::2])
    rows = tuple(np.broadcast_to(b.v, (n,)) for b in ctx.batches)
    bad = ctx.bad.copy()
    for k in set(slots):  # a value written into the file that is not finite: the design's file is refused
        bad |= ctx.batches[k].bad
    return BatchExpansion(parts, slots, rows, bad)


def read_designs(path: str | Path, text: str, args: dict, parameters: dict) -> tuple[
        list[MechanismSpec | None], dict[int, str]]:
    """Every design of the xacro family ``path`` (``parameters``: {name: array of SI values, one per design},
    as for expand_batch), expanded at once and each design's URDF read and checked as any file is
    (files.urdf.read_urdf): (its description, None where it is not read; position -> why it was not: to be
    expanded and read alone for the file's own message).  Unbatchable when the family cannot be expanded at
    once."""
    be = expand_batch(path, text, args, parameters)
    specs: list[MechanismSpec | None] = [None] * len(be.bad)
    why = {}
    for k in range(len(be.bad)):
        if be.bad[k]:
            why[k] = "its expansion fails (xacro's message)"
            continue
        try:
            specs[k] = read_urdf(path, be.design(k))
        except (MechanismFileError, UsageError):
            why[k] = "its file is refused (the reader's message)"
    return specs, why

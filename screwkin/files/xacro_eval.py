"""The checked expression interpreter of xacro's ``${...}`` (see :mod:`.xacro`).

xacro evaluates ``${...}`` with Python's ``eval``; screwkin replaces it with this
interpreter of a subset: numbers, strings, names not starting with ``_``, arithmetic,
comparisons, ``and``/``or``/``not``, ``a if c else b`` and calls of the math functions of
:data:`FUNCTIONS` (also as ``math.NAME``).  Strings are only concatenated and stay under
:data:`MAX_STRING` characters; integers beyond :data:`MAX_INT` become floats.
"""

from __future__ import annotations

import ast
import math
import operator
from typing import Any

from ..errors import quote, shorten

__all__ = ["COMPARE", "CONSTANTS", "FUNCTIONS", "MAX_EXPRESSION", "MAX_INT", "MAX_STRING", "Interpreter", "Refused",
           "XacroEvaluationError", "call_function", "check_expression", "evaluate", "function_name", "power"]

#: Most characters of one ``${...}`` expression, and of a string an expression computes.
MAX_EXPRESSION = 2000
MAX_STRING = 10_000
#: Integers beyond this magnitude become floats in expressions.
MAX_INT = 2**63

#: The functions an expression may call, by name or as ``math.NAME``.
FUNCTIONS = {
    "sin": math.sin, "cos": math.cos, "tan": math.tan, "asin": math.asin, "acos": math.acos,
    "atan": math.atan, "atan2": math.atan2, "sqrt": math.sqrt, "radians": math.radians,
    "degrees": math.degrees, "exp": math.exp, "log": math.log, "floor": math.floor, "ceil": math.ceil,
    "abs": None, "min": None, "max": None, "pow": None,  # ours, below (numbers only, bounded)
}
#: The constants ``math.NAME`` may name (``pi`` alone is xacro's own global).
CONSTANTS = {"pi": math.pi, "e": math.e, "tau": math.tau}


# ------------------------------------------------------------------ the expression subset
_BINARY = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
           ast.FloorDiv: operator.floordiv, ast.Mod: operator.mod, ast.Pow: None}
#: The comparisons an expression may make (files.xacro_batch compares Batch values with them too).
COMPARE = {ast.Eq: operator.eq, ast.NotEq: operator.ne, ast.Lt: operator.lt, ast.LtE: operator.le,
            ast.Gt: operator.gt, ast.GtE: operator.ge}
_UNARY = {ast.UAdd: operator.pos, ast.USub: operator.neg, ast.Not: operator.not_}
_ALLOWED = "numbers, names, arithmetic, comparisons, and/or/not, 'a if c else b' and math functions"


class Refused(Exception):
    """An expression that is well formed but computes what xacro's ``${...}`` may not (text where a number goes)."""


def function_name(node: ast.expr) -> str | None:
    """The name of the function a call may call (``sin`` or ``math.sin``), or None."""
    if isinstance(node, ast.Name) and node.id in FUNCTIONS:
        return node.id
    if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "math" \
            and node.attr in FUNCTIONS:
        return node.attr
    return None


def _describe(node) -> str:
    if isinstance(node, ast.Attribute):
        return f"attribute access '.{shorten(node.attr, 30)}'"
    if isinstance(node, ast.Call):
        try:
            return f"a call of '{shorten(ast.unparse(node.func), 40)}'"
        except Exception:  # noqa: BLE001  # pragma: no cover - unparse of a parsed tree
            return "a call"
    if isinstance(node, ast.Name):
        return f"the name '{shorten(node.id, 30)}'"
    if isinstance(node, (ast.BinOp, ast.UnaryOp, ast.Compare)):
        op = getattr(node, "op", None) or node.ops[0]
        return f"the operator {type(op).__name__}"
    return type(node).__name__


def _check_node(node):
    if isinstance(node, ast.Expression):
        return _check_node(node.body)
    if isinstance(node, ast.Constant):
        if not isinstance(node.value, (int, float, str, bool)) or isinstance(node.value, complex):
            raise Refused(f"the constant {shorten(repr(node.value), 30)}")
        return None
    if isinstance(node, ast.Name):
        if node.id.startswith("_"):
            raise Refused(f"the name '{shorten(node.id, 30)}' (names starting with _ are refused)")
        return None
    if isinstance(node, ast.Attribute):
        if isinstance(node.value, ast.Name) and node.value.id == "math" and node.attr in CONSTANTS:
            return None
        raise Refused(_describe(node))
    if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
        _check_node(node.left)
        return _check_node(node.right)
    if isinstance(node, ast.UnaryOp) and type(node.op) in _UNARY:
        return _check_node(node.operand)
    if isinstance(node, ast.BoolOp):
        for v in node.values:
            _check_node(v)
        return None
    if isinstance(node, ast.Compare) and all(type(op) in COMPARE for op in node.ops):
        _check_node(node.left)
        for c in node.comparators:
            _check_node(c)
        return None
    if isinstance(node, ast.IfExp):
        for v in (node.test, node.body, node.orelse):
            _check_node(v)
        return None
    if isinstance(node, ast.Call):
        if function_name(node.func) is None:
            raise Refused(_describe(node))
        if node.keywords or any(isinstance(a, ast.Starred) for a in node.args):
            raise Refused("keyword or starred arguments")
        for a in node.args:
            _check_node(a)
        return None
    raise Refused(_describe(node))


def _parse_expression(expr: str):
    """The checked syntax tree of an expression (raises Refused)."""
    if len(expr) > MAX_EXPRESSION:
        raise Refused(f"an expression of {len(expr)} characters (at most {MAX_EXPRESSION})")
    if "load_yaml" in expr:
        raise Refused("load_yaml (xacro's YAML loading)")
    try:
        tree = ast.parse(expr.strip(), mode="eval")
    except SyntaxError as exc:
        raise Refused(f"invalid syntax ({shorten(exc.msg or '', 60)})") from None
    except (RecursionError, MemoryError, ValueError):
        raise Refused("an expression nested too deeply") from None
    try:
        _check_node(tree)
    except RecursionError:
        raise Refused("an expression nested too deeply") from None
    return tree


def check_expression(expr: str) -> None:
    """Raise ValueError (with what is refused) unless ``expr`` is in the subset."""
    try:
        _parse_expression(expr)
    except Refused as exc:
        raise ValueError(f"xacro expression {quote(expr, 60)} uses {exc}: only {_ALLOWED} are allowed") from None


def _number(x: str | float) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, complex)


def _bounded(x: str | float) -> str | float:
    if isinstance(x, bool):
        return x
    if isinstance(x, int) and abs(x) > MAX_INT:
        return float(x)
    if isinstance(x, str) and len(x) > MAX_STRING:
        raise Refused(f"a string of more than {MAX_STRING} characters")
    return x


def power(a: Any, b: Any) -> int | float:
    """``a ** b`` as xacro computes it: a bounded int for small int powers, else a float."""
    if not (_number(a) and _number(b)):
        raise Refused("** on text")
    if isinstance(a, int) and isinstance(b, int) and not isinstance(a, bool) and 0 <= b <= 64:
        return _bounded(a ** b)
    return float(a) ** float(b)  # OverflowError when too large


def call_function(name: str, args: list) -> Any:
    """The math function ``name`` (of FUNCTIONS, min, max, pow, abs) of ``args``, numbers only."""
    if not all(_number(a) for a in args):
        raise Refused(f"{name}() of text")
    if name == "abs":
        if len(args) != 1:
            raise TypeError("abs() takes one argument")
        return abs(args[0])
    if name in ("min", "max"):
        if not args:
            raise TypeError(f"{name}() needs at least one argument")
        return (min if name == "min" else max)(args)
    if name == "pow":
        if len(args) != 2:
            raise TypeError("pow() takes two arguments")
        return power(*args)
    return _bounded(FUNCTIONS[name](*args))


class Interpreter:
    """Evaluates a checked tree with names looked up in xacro's symbol table."""

    def __init__(self, symbols) -> None:
        self.symbols = symbols

    def value(self, node):
        if isinstance(node, ast.Expression):
            return self.value(node.body)
        if isinstance(node, ast.Constant):
            return _bounded(node.value)
        if isinstance(node, ast.Name):
            try:
                v = self.symbols[node.id]
            except KeyError:
                raise NameError(f"name '{node.id}' is not defined") from None
            if isinstance(v, bool) or _number(v) or isinstance(v, str):
                return v
            raise Refused(f"the name '{shorten(node.id, 30)}', which is not a number or text")
        if isinstance(node, ast.Attribute):  # math.pi, math.e, math.tau (checked)
            return CONSTANTS[node.attr]
        if isinstance(node, ast.BinOp):
            a, b = self.value(node.left), self.value(node.right)
            if isinstance(node.op, ast.Pow):
                return power(a, b)
            if isinstance(a, str) or isinstance(b, str):
                if isinstance(node.op, ast.Add) and isinstance(a, str) and isinstance(b, str):
                    return _bounded(a + b)
                raise Refused(f"the operator {type(node.op).__name__} on text (text is only joined with +)")
            return _bounded(_BINARY[type(node.op)](a, b))
        if isinstance(node, ast.UnaryOp):
            v = self.value(node.operand)
            if isinstance(v, str) and not isinstance(node.op, ast.Not):
                raise Refused("a sign on text")
            return _UNARY[type(node.op)](v)
        if isinstance(node, ast.BoolOp):
            and_ = isinstance(node.op, ast.And)
            v = None
            for item in node.values:
                v = self.value(item)
                if bool(v) != and_:
                    return v
            return v
        if isinstance(node, ast.Compare):
            left = self.value(node.left)
            for op, right_node in zip(node.ops, node.comparators):
                right = self.value(right_node)
                if isinstance(left, str) != isinstance(right, str) and type(op) not in (ast.Eq, ast.NotEq):
                    raise Refused("an order comparison of text with a number")
                if not COMPARE[type(op)](left, right):
                    return False
                left = right
            return True
        if isinstance(node, ast.IfExp):
            return self.value(node.body) if self.value(node.test) else self.value(node.orelse)
        if isinstance(node, ast.Call):
            return call_function(function_name(node.func), [self.value(a) for a in node.args])
        raise Refused(_describe(node))  # pragma: no cover - checked before


class XacroEvaluationError(Exception):
    """An expression xacro asked to evaluate is refused or fails (xacro adds its context)."""


def evaluate(expr: str, symbols=None, interpreter=None) -> str | float:
    """The value of a ``${...}`` expression (its inside) with names from ``symbols`` (a
    mapping; xacro's symbol table while expanding): the subset of :func:`check_expression`,
    evaluated without ``eval`` (by ``interpreter(symbols)``, default this module's; files.xacro_batch
    gives one that computes with arrays)."""
    try:
        tree = _parse_expression(expr)
        return (interpreter or Interpreter)({} if symbols is None else symbols).value(tree)
    except Refused as exc:
        raise XacroEvaluationError(f"refused: {exc} (only {_ALLOWED} are allowed)") from None
    except RecursionError:
        raise XacroEvaluationError("properties defined through each other too deeply") from None
    except OverflowError:
        raise XacroEvaluationError("a number too large (overflow)") from None

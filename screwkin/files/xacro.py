"""Parametric mechanism files: xacro (``.urdf.xacro``) expanded safely into URDF text.

One xacro file describes a family of mechanisms: ``<xacro:arg name="a" default="0.04"/>``
declares an argument, ``$(arg a)`` reads it, ``${...}`` computes with it, macros repeat
a leg.  The expansion is the PyPI ``xacro`` package's own (``xacro.process_doc``), but a
xacro file is untrusted like any mechanism file, and xacro evaluates ``${...}`` with
Python's ``eval``, resolves ``$(env ...)``, ``$(find ...)``, ``$(eval ...)``, loads YAML
and includes any file.  So, besides the XML protections of :mod:`.xmlsafe` (bounded
size, no entities, bounded nesting):

* before xacro sees the file, every attribute and text is checked: each ``${...}`` must
  parse (Python's ``ast``) as numbers, strings, names not starting with ``_``,
  arithmetic, comparisons, ``and``/``or``/``not``, ``a if c else b`` and calls of the
  math functions of :data:`FUNCTIONS` (also as ``math.NAME``); the only substitution is
  ``$(arg NAME)``; ``load_yaml`` and includes of files outside the file's folder are
  refused;
* while xacro runs, its evaluator is replaced by an interpreter of that same subset
  (:func:`evaluate`): nothing reaches ``eval``, strings are only concatenated and
  stay under :data:`MAX_STRING` characters, integers beyond 2**63 become floats
  (``9**9**9`` is an overflow, not an hour of work), and the text an argument puts into
  an expression is checked like the file's own; its ``$(...)`` handler accepts ``arg``
  only; its includes are read with the same bounds and checks (at most
  :data:`MAX_INCLUDES` files, all inside the first file's folder, no wildcards);
  macro expansion is bounded (at most :data:`MAX_MACRO_CALLS` calls and ``LIMITS.elements``
  elements copied in all).

xacro keeps its state in module globals, so one expansion runs at a time in a process
(a lock); a study runs designs in separate processes.
"""

from __future__ import annotations

import ast
import contextlib
import io
import math
import operator
import os
import re
import threading
import xml.dom.minidom
from dataclasses import dataclass, field
from pathlib import Path

import defusedxml
import defusedxml.minidom

from ..errors import MechanismFileError, UsageError, quote, shorten
from ..units import parse_value
from .description import LIMITS
from .xmlsafe import parse_xml_text, read_regular_file

__all__ = ["FUNCTIONS", "MAX_INCLUDES", "MAX_STRING", "check_expression", "declared_args", "evaluate", "expand",
           "is_xacro", "normalize_args", "parse_args"]

XACRO_NAMESPACES = ("http://www.ros.org/wiki/xacro", "http://ros.org/wiki/xacro")
#: Most files one expansion reads (the first one and its includes).
MAX_INCLUDES = 50
#: Most characters of one ``${...}`` expression, and of a string an expression computes.
MAX_EXPRESSION = 2000
MAX_STRING = 10_000
#: Integers beyond this magnitude become floats in expressions.
MAX_INT = 2**63
#: Most characters of an argument's value.
MAX_ARG = 1000
#: Most macro calls one expansion makes (a Delta makes 17; robots of a hundred links a few hundred).
MAX_MACRO_CALLS = 5000
#: Most deep copies of elements one expansion makes (macro bodies and inserted blocks; each costs xacro
#: about 0.2 ms to evaluate, so this bounds a file's expansion to about a second).
MAX_COPIES = 5000

#: The functions an expression may call, by name or as ``math.NAME``.
FUNCTIONS = {
    "sin": math.sin, "cos": math.cos, "tan": math.tan, "asin": math.asin, "acos": math.acos,
    "atan": math.atan, "atan2": math.atan2, "sqrt": math.sqrt, "radians": math.radians,
    "degrees": math.degrees, "exp": math.exp, "log": math.log, "floor": math.floor, "ceil": math.ceil,
    "abs": None, "min": None, "max": None, "pow": None,  # ours, below (numbers only, bounded)
}
#: The constants ``math.NAME`` may name (``pi`` alone is xacro's own global).
CONSTANTS = {"pi": math.pi, "e": math.e, "tau": math.tau}

_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")
# xacro's lexer (xacro.LEXER): $$( and $${ escape, ${...} up to the first }, $(...) up to the first )
_TOKENS = re.compile(r"\$\$+[{(]|\$\{[^}]*\}|\$\([^)]*\)")
_EXTENSION = re.compile(r"\$\([^)]*\)")
_ARG = re.compile(r"\s*arg\s+([A-Za-z][A-Za-z0-9_]*)\s*\Z")
_GLOB = re.compile(r"[*?\[]")
_LOCK = threading.Lock()


def _xacro_tag(tag: str):
    """The local name of an element in the xacro namespace (ElementTree's ``{uri}name``), or None."""
    if tag.startswith("{"):
        uri, _, local = tag[1:].partition("}")
        if uri.rstrip("/") in XACRO_NAMESPACES:
            return local
    return None


def is_xacro(path, text: str) -> bool:
    """A xacro file: its name ends in ``.xacro`` or it declares the ``xacro`` namespace."""
    return str(path).lower().endswith(".xacro") or re.search(r"xmlns:xacro\s*=", text) is not None


# ------------------------------------------------------------------ arguments
def _arg_value(name: str, value, where: str) -> str:
    """The text xacro receives for an argument: numbers as typed, values with a unit in SI
    (``30mm`` -> ``0.03``), other text as it is (bounded, printable)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        if not math.isfinite(value):
            raise UsageError(f"{where}: argument {quote(name)} is {value!r}, not a finite number")
        return repr(value) if isinstance(value, float) else str(int(value))
    if not isinstance(value, str):
        raise UsageError(f"{where}: argument {quote(name)} must be a number or text, got {quote(value)}")
    if len(value) > MAX_ARG or not value.isprintable():
        raise UsageError(f"{where}: the value of argument {quote(name)} is over {MAX_ARG} characters or holds "
                         "control characters")
    text = value.strip()
    try:
        number = parse_value(text)
    except UsageError:
        return value  # not a number: text (a prefix, a colour name)
    if re.fullmatch(r"[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?", text):
        return text  # a bare number as typed (an integer stays an integer)
    return repr(number)


def normalize_args(args, where: str = "arguments") -> dict:
    """{name: value} (numbers, text with units) -> {name: text for xacro}, names checked."""
    out = {}
    for name, value in dict(args or {}).items():
        if not isinstance(name, str) or not _NAME.match(name):
            raise UsageError(f"{where}: {quote(name)} is not a xacro argument name (letters, digits, _)")
        out[name] = _arg_value(name, value, where)
    return out


def parse_args(items, option: str = "--arg") -> dict:
    """``["a=30mm", "b=0.1"]`` -> ``{"a": "0.03", "b": "0.1"}`` (see :func:`normalize_args`)."""
    out = {}
    for item in items or []:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            raise UsageError(f"{option} expects NAME=VALUE, got {quote(item)}")
        if name.strip() in out:
            raise UsageError(f"{option}: argument {quote(name.strip())} is given twice")
        out[name.strip()] = value
    return normalize_args(out, option)


# ------------------------------------------------------------------ the expression subset
_BINARY = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
           ast.FloorDiv: operator.floordiv, ast.Mod: operator.mod, ast.Pow: None}
_COMPARE = {ast.Eq: operator.eq, ast.NotEq: operator.ne, ast.Lt: operator.lt, ast.LtE: operator.le,
            ast.Gt: operator.gt, ast.GtE: operator.ge}
_UNARY = {ast.UAdd: operator.pos, ast.USub: operator.neg, ast.Not: operator.not_}
_ALLOWED = "numbers, names, arithmetic, comparisons, and/or/not, 'a if c else b' and math functions"


class _Refused(Exception):
    pass


def _function_name(node):
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


def _check_node(node) -> None:
    if isinstance(node, ast.Expression):
        return _check_node(node.body)
    if isinstance(node, ast.Constant):
        if not isinstance(node.value, (int, float, str, bool)) or isinstance(node.value, complex):
            raise _Refused(f"the constant {shorten(repr(node.value), 30)}")
        return None
    if isinstance(node, ast.Name):
        if node.id.startswith("_"):
            raise _Refused(f"the name '{shorten(node.id, 30)}' (names starting with _ are refused)")
        return None
    if isinstance(node, ast.Attribute):
        if isinstance(node.value, ast.Name) and node.value.id == "math" and node.attr in CONSTANTS:
            return None
        raise _Refused(_describe(node))
    if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
        _check_node(node.left)
        return _check_node(node.right)
    if isinstance(node, ast.UnaryOp) and type(node.op) in _UNARY:
        return _check_node(node.operand)
    if isinstance(node, ast.BoolOp):
        for v in node.values:
            _check_node(v)
        return None
    if isinstance(node, ast.Compare) and all(type(op) in _COMPARE for op in node.ops):
        _check_node(node.left)
        for c in node.comparators:
            _check_node(c)
        return None
    if isinstance(node, ast.IfExp):
        for v in (node.test, node.body, node.orelse):
            _check_node(v)
        return None
    if isinstance(node, ast.Call):
        if _function_name(node.func) is None:
            raise _Refused(_describe(node))
        if node.keywords or any(isinstance(a, ast.Starred) for a in node.args):
            raise _Refused("keyword or starred arguments")
        for a in node.args:
            _check_node(a)
        return None
    raise _Refused(_describe(node))


def _parse_expression(expr: str):
    """The checked syntax tree of an expression (raises _Refused)."""
    if len(expr) > MAX_EXPRESSION:
        raise _Refused(f"an expression of {len(expr)} characters (at most {MAX_EXPRESSION})")
    if "load_yaml" in expr:
        raise _Refused("load_yaml (xacro's YAML loading)")
    try:
        tree = ast.parse(expr.strip(), mode="eval")
    except SyntaxError as exc:
        raise _Refused(f"invalid syntax ({shorten(exc.msg or '', 60)})") from None
    except (RecursionError, MemoryError, ValueError):
        raise _Refused("an expression nested too deeply") from None
    try:
        _check_node(tree)
    except RecursionError:
        raise _Refused("an expression nested too deeply") from None
    return tree


def check_expression(expr: str) -> None:
    """Raise ValueError (with what is refused) unless ``expr`` is in the subset."""
    try:
        _parse_expression(expr)
    except _Refused as exc:
        raise ValueError(f"xacro expression {quote(expr, 60)} uses {exc}: only {_ALLOWED} are allowed") from None


def _number(x):
    return isinstance(x, (int, float)) and not isinstance(x, complex)


def _bounded(x):
    if isinstance(x, bool):
        return x
    if isinstance(x, int) and abs(x) > MAX_INT:
        return float(x)
    if isinstance(x, str) and len(x) > MAX_STRING:
        raise _Refused(f"a string of more than {MAX_STRING} characters")
    return x


def _power(a, b):
    if not (_number(a) and _number(b)):
        raise _Refused("** on text")
    if isinstance(a, int) and isinstance(b, int) and not isinstance(a, bool) and 0 <= b <= 64:
        return _bounded(a ** b)
    return float(a) ** float(b)  # OverflowError when too large


def _call(name, args):
    if not all(_number(a) for a in args):
        raise _Refused(f"{name}() of text")
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
        return _power(*args)
    return _bounded(FUNCTIONS[name](*args))


class _Interpreter:
    """Evaluates a checked tree with names looked up in xacro's symbol table."""

    def __init__(self, symbols):
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
            raise _Refused(f"the name '{shorten(node.id, 30)}', which is not a number or text")
        if isinstance(node, ast.Attribute):  # math.pi, math.e, math.tau (checked)
            return CONSTANTS[node.attr]
        if isinstance(node, ast.BinOp):
            a, b = self.value(node.left), self.value(node.right)
            if isinstance(node.op, ast.Pow):
                return _power(a, b)
            if isinstance(a, str) or isinstance(b, str):
                if isinstance(node.op, ast.Add) and isinstance(a, str) and isinstance(b, str):
                    return _bounded(a + b)
                raise _Refused(f"the operator {type(node.op).__name__} on text (text is only joined with +)")
            return _bounded(_BINARY[type(node.op)](a, b))
        if isinstance(node, ast.UnaryOp):
            v = self.value(node.operand)
            if isinstance(v, str) and not isinstance(node.op, ast.Not):
                raise _Refused("a sign on text")
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
                    raise _Refused("an order comparison of text with a number")
                if not _COMPARE[type(op)](left, right):
                    return False
                left = right
            return True
        if isinstance(node, ast.IfExp):
            return self.value(node.body) if self.value(node.test) else self.value(node.orelse)
        if isinstance(node, ast.Call):
            return _call(_function_name(node.func), [self.value(a) for a in node.args])
        raise _Refused(_describe(node))  # pragma: no cover - checked before


class XacroEvaluationError(Exception):
    """An expression xacro asked to evaluate is refused or fails (xacro adds its context)."""


def evaluate(expr: str, symbols=None):
    """The value of a ``${...}`` expression (its inside) with names from ``symbols`` (a
    mapping; xacro's symbol table while expanding): the subset of :func:`check_expression`,
    evaluated without ``eval``."""
    try:
        tree = _parse_expression(expr)
        return _Interpreter({} if symbols is None else symbols).value(tree)
    except _Refused as exc:
        raise XacroEvaluationError(f"refused: {exc} (only {_ALLOWED} are allowed)") from None
    except RecursionError:
        raise XacroEvaluationError("properties defined through each other too deeply") from None
    except OverflowError:
        raise XacroEvaluationError("a number too large (overflow)") from None


# ------------------------------------------------------------------ checking the files
@dataclass
class _State:
    """One expansion: the first file's folder, the files read, the arguments declared."""

    top: Path
    folder: Path
    files: list = field(default_factory=list)
    bytes: int = 0
    declared: dict = field(default_factory=dict)  # name -> default text or None
    copied: int = 0  # elements copied by macro expansion
    calls: int = 0
    copies: int = 0  # deep copies of elements (macro bodies, inserted blocks)


def _check_text(text: str, path, state: _State) -> None:
    """Every ``${...}`` and ``$(...)`` of an attribute or text."""
    if not text or "$" not in text:
        return
    for m in _TOKENS.finditer(text):
        token = m.group(0)
        if token.startswith("$$"):
            continue
        if token.startswith("$("):
            _check_extension(token, path)
            continue
        inner = token[2:-1]
        for ext in _EXTENSION.findall(inner):
            _check_extension(ext, path)
        try:
            check_expression(_EXTENSION.sub("0", inner))
        except ValueError as exc:
            raise MechanismFileError(path, str(exc)) from None


def _check_extension(token: str, path) -> None:
    inner = token[2:-1]
    if _ARG.match(inner):
        return
    word = (inner.split() or ["$()"])[0]
    raise MechanismFileError(path, f"xacro substitution {quote(token, 60)} is refused: only $(arg NAME) is allowed "
                                   f"({quote(word, 20)} would read the environment, other files or run code)")


def _inside(state: _State, target: Path) -> bool:
    try:
        return Path(os.path.realpath(target)).is_relative_to(state.folder)
    except (OSError, ValueError):
        return False


def _include_path(spec: str, current: Path, path, state: _State) -> Path:
    if _GLOB.search(spec):
        raise MechanismFileError(path, f"xacro:include {quote(spec, 60)}: wildcards are refused")
    target = Path(spec) if os.path.isabs(spec) else current.parent / spec
    if not _inside(state, target):
        raise MechanismFileError(path, f"xacro:include {quote(spec, 60)} is outside the folder of "
                                       f"{quote(state.top.name)} (refused: a mechanism file reads only files beside it "
                                       "or below)")
    return target


def _read_file(target: Path, path, state: _State):
    """(text, ElementTree root) of an included file: bounded, checked, counted."""
    if len(state.files) >= MAX_INCLUDES:
        raise MechanismFileError(path, f"more than {MAX_INCLUDES} files included (refused)")
    raw = read_regular_file(target, LIMITS.file_bytes, "xacro file")
    state.bytes += len(raw)
    if state.bytes > LIMITS.file_bytes:
        raise MechanismFileError(path, f"the file and its includes are over {LIMITS.file_bytes / 1e6:g} MB")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise MechanismFileError(target, "not a text file (not UTF-8)") from None
    state.files.append(target)
    root = parse_xml_text(text, target)
    return text, root


def _check_tree(root, path: Path, state: _State, follow: bool = True) -> None:
    """Check one file's tree; collect its xacro:arg declarations; follow its literal includes."""
    for elem in root.iter():
        for value in elem.attrib.values():
            _check_text(value, path, state)
        _check_text(elem.text, path, state)
        _check_text(elem.tail, path, state)
        local = _xacro_tag(elem.tag) if isinstance(elem.tag, str) else None
        if local == "arg":
            name = elem.get("name")
            if name and name not in state.declared:
                state.declared[name] = elem.get("default")
        elif local == "include" and follow:
            spec = elem.get("filename")
            if spec is None:
                raise MechanismFileError(path, "xacro:include without a filename")
            if "$" in spec:
                continue  # computed: checked when xacro includes it
            target = _include_path(spec, path, path, state)
            if target in state.files:
                continue
            _, sub = _read_file(target, path, state)
            _check_tree(sub, target, state)


def _prepare(path, text, root=None) -> _State:
    path = Path(path)
    state = _State(path, Path(os.path.realpath(path.parent if str(path.parent) else ".")))
    state.files.append(path)
    state.bytes = len(text.encode("utf-8", "replace"))
    if root is None:
        root = parse_xml_text(text, path)
    _check_tree(root, path, state)
    return state


def declared_args(path, text: str | None = None) -> dict:
    """The arguments a xacro file declares (``xacro:arg``, its literal includes' too):
    {name: default text, or None when it has none}.  The file is checked as for :func:`expand`."""
    if text is None:
        raw = read_regular_file(path, LIMITS.file_bytes, "mechanism file")
        try:
            text = raw.decode("utf-8-sig")
        except UnicodeDecodeError:
            raise MechanismFileError(path, "not a text file (not UTF-8)") from None
    return dict(_prepare(path, text).declared)


# ------------------------------------------------------------------ expansion
def _one_line(exc) -> str:
    """xacro's message on one line, with only the innermost of its nested "when evaluating
    expression" contexts (a property defined through others repeats each)."""
    text = " ".join(str(exc).split())
    parts = text.split(" when evaluating expression ")
    return " when evaluating expression ".join(parts[:2]) or type(exc).__name__


def _patched(xacro, state: _State, path):
    """Replace xacro's evaluator, substitutions, includes and macro calls while expanding."""
    original = {k: getattr(xacro, k) for k in ("safe_eval", "eval_extension", "get_include_files", "parse",
                                                "handle_macro_call", "eval_text")}

    def eval_text(text, symbols):
        # "${s}${s}" is concatenated here, by xacro, not by our interpreter: a property defined as twice the
        # previous one doubles at each level (2**40 characters from a 2 kB file)
        result = original["eval_text"](text, symbols)
        if isinstance(result, str) and len(result) > max(MAX_STRING, len(text)):
            raise xacro.XacroException(f"text grows past {MAX_STRING} characters by substitution (refused: "
                                       "properties that double?)")
        return result

    def safe_eval(expr, globals, locals=None):
        try:
            return evaluate(expr, globals)
        except XacroEvaluationError as exc:  # xacro wraps it with "when evaluating expression ..."
            raise xacro.XacroException(str(exc)) from None

    def eval_extension(s):
        m = _ARG.match(s[2:-1])
        if not m:
            raise MechanismFileError(path, f"xacro substitution {quote(s, 60)} is refused: only $(arg NAME) is "
                                           "allowed")
        known = xacro.substitution_args_context.get("arg", {})
        if m.group(1) not in known:
            raise MechanismFileError(path, f"xacro argument {quote(m.group(1))} has no value: give it "
                                           f"(--arg {m.group(1)}=VALUE) or declare it first with "
                                           f"<xacro:arg name=\"{m.group(1)}\" default=\"...\"/>")
        return known[m.group(1)]

    def get_include_files(filename_spec, symbols):
        spec = str(xacro.eval_text(filename_spec, symbols))
        current = Path(xacro.filestack[-1]) if xacro.filestack and xacro.filestack[-1] else state.top
        yield str(_include_path(spec, current, path, state))

    def parse(inp, filename=None):
        if inp is not None:
            return original["parse"](inp, filename)
        target = Path(filename)
        if not _inside(state, target):  # pragma: no cover - get_include_files checked it
            raise MechanismFileError(path, f"xacro:include {quote(str(filename), 60)} is outside the file's folder")
        text, root = _read_file(target, path, state)
        _check_tree(root, target, state, follow=False)
        return _dom(text, target)

    def handle_macro_call(node, macros, symbols):
        if node.tagName.startswith("xacro:"):
            state.calls += 1
            if state.calls > MAX_MACRO_CALLS:
                raise MechanismFileError(path, f"more than {MAX_MACRO_CALLS} macro calls (refused: recursive macros?)")
            name = node.tagName[6:]
            if name == "call":
                name = str(xacro.eval_text(node.getAttribute("macro") or "", symbols))
            try:
                body = xacro.resolve_macro(name, macros, symbols)[2].body
            except (KeyError, AttributeError, TypeError):
                body = None
            if body is not None:
                size = len(body.getElementsByTagName("*")) + 1
                blocks = len(body.getElementsByTagName("xacro:insert_block"))
                state.copied += size + blocks * (len(node.getElementsByTagName("*")) + 1)
                if state.copied > LIMITS.elements:
                    raise MechanismFileError(path, f"the macros expand to more than {LIMITS.elements} elements "
                                                   "(refused)")
        return original["handle_macro_call"](node, macros, symbols)

    replaced = {"safe_eval": safe_eval, "eval_extension": eval_extension, "get_include_files": get_include_files,
                "parse": parse, "handle_macro_call": handle_macro_call, "eval_text": eval_text}
    return original, replaced


@contextlib.contextmanager
def _counted_copies(state: _State, path):
    """While xacro runs, every deep copy of an element (an ``insert_block`` of a block property or a
    macro's block parameter, a macro body) adds its elements to ``state.copied``; past LIMITS.elements
    the expansion stops at once.  Property blocks that insert the previous one twice double at each
    level without a single macro call: 16 levels are 65,536 copies from a 1.9 kB file."""
    element = xml.dom.minidom.Element
    original = element.cloneNode

    def cloneNode(self, deep):
        clone = original(self, deep)
        if deep:
            state.copies += 1
            state.copied += len(clone.getElementsByTagName("*")) + 1
            if state.copies > MAX_COPIES or state.copied > LIMITS.elements:
                raise MechanismFileError(path, "the xacro blocks and macros make more than "
                                               + (f"{MAX_COPIES} copies" if state.copies > MAX_COPIES else
                                                  f"{LIMITS.elements} elements")
                                               + " (refused: blocks that insert each other twice?)")
        return clone

    element.cloneNode = cloneNode
    try:
        yield
    finally:
        element.cloneNode = original


def _dom(text: str, path):
    """A minidom document of checked text (defusedxml: no entities, no external references)."""
    try:
        return defusedxml.minidom.parseString(text.encode("utf-8"), forbid_dtd=False, forbid_entities=True,
                                              forbid_external=True)
    except (defusedxml.DefusedXmlException, ValueError) as exc:
        raise MechanismFileError(path, f"XML refused: {shorten(str(exc), 100)}") from None
    except Exception as exc:  # noqa: BLE001 - expat errors (checked before: should not happen)
        raise MechanismFileError(path, f"malformed XML: {shorten(_one_line(exc), 100)}") from None


def expand(path, text: str, args=None, root=None, warn=None) -> str:
    """The URDF text of xacro file ``path`` (whose text is ``text``) with arguments
    ``args`` ({name: value}; see :func:`normalize_args`).  Raises MechanismFileError (the
    file's problem, one line) or UsageError (an argument the file does not declare).

    warn: callable receiving xacro's own warnings (default: dropped)."""
    import xacro  # lazily: only xacro files need it (it also patches minidom's pretty printer on import)

    path = Path(path)
    given = normalize_args(args, str(path))
    state = _prepare(path, text, root)
    unknown = [n for n in given if n not in state.declared]
    if unknown:
        known = ", ".join(sorted(state.declared)) or "none"
        raise UsageError(f"{path}: the file declares no xacro argument {quote(unknown[0])} (its arguments: {known})")
    missing = [n for n, d in state.declared.items() if d is None and n not in given]
    if missing:
        raise MechanismFileError(path, f"xacro argument {quote(missing[0])} has no default: give it "
                                       f"(--arg {missing[0]}=VALUE)")
    doc = _dom(text, path)
    for elem in doc.getElementsByTagName("xacro:arg"):  # xacro requires a default; ours may be given instead
        if not elem.hasAttribute("default"):
            elem.setAttribute("default", "")
    output = io.StringIO()
    with _LOCK:
        original, replaced = _patched(xacro, state, path)
        saved_verbosity = xacro.verbosity
        try:
            for k, f in replaced.items():
                setattr(xacro, k, f)
            xacro.init_stacks(str(path))
            with contextlib.redirect_stderr(output), contextlib.redirect_stdout(output), _counted_copies(state, path):
                xacro.process_doc(doc, mappings=dict(given), verbosity=0)
            result = doc.toxml()
        except MechanismFileError:
            raise
        except RecursionError:
            raise MechanismFileError(path, "xacro: macros or properties nested too deeply (recursive?)") from None
        except xacro.XacroException as exc:
            raise MechanismFileError(path, f"xacro: {shorten(_one_line(exc), 240)}") from None
        except Exception as exc:  # noqa: BLE001 - xacro's own errors are not all XacroException (RuntimeError, KeyError...)
            raise MechanismFileError(path, f"xacro: {type(exc).__name__}: {shorten(_one_line(exc), 200)}") from None
        finally:
            for k, f in original.items():
                setattr(xacro, k, f)
            xacro.verbosity = saved_verbosity
            xacro.substitution_args_context["arg"] = {}
            del xacro.all_includes[:]
    if warn is not None:
        for line in output.getvalue().splitlines():
            line = re.sub(r"\x1b\[[0-9;]*m", "", line).strip()
            if line and not line.startswith(("when processing file", "in file", "included from", "when instantiating",
                                             "instantiated from")):
                warn(f"xacro: {line.removeprefix('warning: ')}")
    if len(result) > LIMITS.file_bytes:
        raise MechanismFileError(path, f"the expanded URDF is over {LIMITS.file_bytes / 1e6:g} MB")
    return result

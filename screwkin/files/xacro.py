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
  math functions of :data:`xacro_eval.FUNCTIONS` (also as ``math.NAME``); the only substitution is
  ``$(arg NAME)``; ``load_yaml`` and includes of files outside the file's folder are
  refused;
* while xacro runs, its evaluator is replaced by an interpreter of that same subset
  (:func:`evaluate`, in :mod:`.xacro_eval`): nothing reaches ``eval``, strings are only concatenated and
  stay under :data:`MAX_STRING` characters, integers beyond 2**63 become floats
  (``9**9**9`` is an overflow, not an hour of work), and the text an argument puts into
  an expression is checked like the file's own; its ``$(...)`` handler accepts ``arg``
  only; its includes are read with the same bounds and checks (at most
  :data:`MAX_INCLUDES` files, all inside the first file's folder, no wildcards);
  macro expansion is bounded (at most :data:`MAX_MACRO_CALLS` calls and ``LIMITS.elements``
  elements copied in all), and so are the copies ``xacro:insert_block`` makes: before a
  block is copied, the size it expands to (its blocks inserted in it, recursively) is
  counted against the same bound, so a block of two copies of a block of two copies ...
  is refused at once, not after minutes of copying.

A ``XacroException`` of xacro is the file's mistake (exit 1); any other exception from
inside the xacro package is reported as an internal error of the xacro expansion (exit 3).

xacro keeps its state in module globals, so one expansion runs at a time in a process
(a lock); a study runs designs in separate processes.
"""

from __future__ import annotations

import contextlib
import io
import math
import os
import re
import threading
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any


from ..errors import MechanismFileError, UsageError, quote, shorten
from ..units import parse_value
from .description import LIMITS
from .xacro_eval import MAX_STRING, XacroEvaluationError, check_expression, evaluate
from .xmlsafe import inside_folder, parse_xml_text, read_regular_file

if TYPE_CHECKING:
    from xml.dom.minidom import Element as MinidomElement

__all__ = ["MAX_INCLUDES", "XacroInternalError", "declared_args", "expand", "is_xacro", "normalize_args", "parse_args"]

XACRO_NAMESPACES = ("http://www.ros.org/wiki/xacro", "http://ros.org/wiki/xacro")
#: Most files one expansion reads (the first one and its includes).
MAX_INCLUDES = 50
#: Most characters of an argument's value.
MAX_ARG = 1000
#: Most macro calls one expansion makes (a Delta makes 17; robots of a hundred links a few hundred).
MAX_MACRO_CALLS = 5000


_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")
# xacro's lexer (xacro.LEXER): $$( and $${ escape, ${...} up to the first }, $(...) up to the first )
_TOKENS = re.compile(r"\$\$+[{(]|\$\{[^}]*\}|\$\([^)]*\)")
_EXTENSION = re.compile(r"\$\([^)]*\)")
_ARG = re.compile(r"\s*arg\s+([A-Za-z][A-Za-z0-9_]*)\s*\Z")
_GLOB = re.compile(r"[*?\[]")
_LOCK = threading.Lock()


def _xacro_tag(tag: str) -> str | None:
    """The local name of an element in the xacro namespace (ElementTree's ``{uri}name``), or None."""
    if tag.startswith("{"):
        uri, _, local = tag[1:].partition("}")
        if uri.rstrip("/") in XACRO_NAMESPACES:
            return local
    return None


def is_xacro(path: Path | str, text: str) -> bool:
    """A xacro file: its name ends in ``.xacro`` or it declares the ``xacro`` namespace."""
    return str(path).lower().endswith(".xacro") or re.search(r"xmlns:xacro\s*=", text) is not None


# ------------------------------------------------------------------ arguments
def _arg_value(name: str, value: str | float, where: str) -> str:
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


def normalize_args(args: dict | None, where: str = "arguments") -> dict:
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


def _check_text(text: str, path: Path, state: _State) -> None:
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


def _check_extension(token: str, path: Path) -> None:
    inner = token[2:-1]
    if _ARG.match(inner):
        return
    word = (inner.split() or ["$()"])[0]
    raise MechanismFileError(path, f"xacro substitution {quote(token, 60)} is refused: only $(arg NAME) is allowed "
                                   f"({quote(word, 20)} would read the environment, other files or run code)")


def _include_path(spec: str, current: Path, path, state: _State) -> Path:
    if _GLOB.search(spec):
        raise MechanismFileError(path, f"xacro:include {quote(spec, 60)}: wildcards are refused")
    target = Path(spec) if os.path.isabs(spec) else current.parent / spec
    if not inside_folder(target, state.folder):
        raise MechanismFileError(path, f"xacro:include {quote(spec, 60)} is outside the folder of "
                                       f"{quote(state.top.name)} (refused: a mechanism file reads only files beside it "
                                       "or below)")
    return target


def _read_file(target: Path, path, state: _State) -> tuple:
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


def _prepare(path: Path, text: str, root=None) -> _State:
    path = Path(path)
    state = _State(path, Path(os.path.realpath(path.parent if str(path.parent) else ".")))
    state.files.append(path)
    state.bytes = len(text.encode("utf-8", "replace"))
    if root is None:
        root = parse_xml_text(text, path)
    _check_tree(root, path, state)
    return state


def declared_args(path: str | Path, text: str | None = None) -> dict:
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
def _one_line(exc: BaseException) -> str:
    """xacro's message on one line, with only the innermost of its nested "when evaluating
    expression" contexts (a property defined through others repeats each)."""
    text = " ".join(str(exc).split())
    parts = text.split(" when evaluating expression ")
    return " when evaluating expression ".join(parts[:2]) or type(exc).__name__


def _block_named(name: str, symbols: dict) -> MinidomElement | None:
    """The block ``xacro:insert_block name=...`` inserts (a property block or a macro's block
    parameter), or None."""
    for key in ("**" + name, "*" + name):
        if key in symbols:
            block = symbols[key]
            return block if hasattr(block, "getElementsByTagName") else None
    return None


def _block_size(block: MinidomElement, symbols: dict, seen: frozenset[int], memo: dict[int, int]) -> int:
    """Elements one copy of ``block`` expands to, its own insert_blocks expanded (capped)."""
    size = 0
    for elem in [block, *block.getElementsByTagName("*")] if block.nodeType == block.ELEMENT_NODE else []:
        if elem.tagName != "xacro:insert_block":
            size += 1
            continue
        inner = _block_named(elem.getAttribute("name"), symbols)
        if inner is None or id(inner) in seen:
            continue  # undefined (xacro says so) or inserted in itself (nested too deeply)
        if id(inner) not in memo:
            memo[id(inner)] = _block_size(inner, symbols, seen | {id(inner)}, memo)
        size += memo[id(inner)]
        if size > LIMITS.elements:
            break
    return size


class _Patches:
    """xacro's functions replaced while expanding ``path``: its evaluator (``evaluator``), substitutions,
    includes and macro calls, each bounded and checked (the originals in ``original``)."""

    NAMES = ("safe_eval", "eval_extension", "get_include_files", "parse", "handle_macro_call", "eval_all",
             "eval_text", "reqd_attrs")

    def __init__(self, xacro: ModuleType, state: _State, path: str | Path,
                 evaluator: Callable[..., Any]) -> None:
        self.xacro, self.state, self.path, self.evaluator = xacro, state, path, evaluator
        self.original = {k: getattr(xacro, k) for k in self.NAMES}

    def replaced(self) -> dict[str, Callable[..., Any]]:
        """Name -> the function that replaces xacro's."""
        return {k: getattr(self, k) for k in self.NAMES}

    def safe_eval(self, expr: str, globals: dict, locals: dict | None = None) -> Any:
        try:
            return self.evaluator(expr, globals)
        except XacroEvaluationError as exc:  # xacro wraps it with "when evaluating expression ..."
            raise self.xacro.XacroException(str(exc)) from None

    def eval_extension(self, s: str) -> str:
        path = self.path
        m = _ARG.match(s[2:-1])
        if not m:
            raise MechanismFileError(path, f"xacro substitution {quote(s, 60)} is refused: only $(arg NAME) is "
                                           "allowed")
        known = self.xacro.substitution_args_context.get("arg", {})
        if m.group(1) not in known:
            raise MechanismFileError(path, f"xacro argument {quote(m.group(1))} has no value: give it "
                                           f"(--arg {m.group(1)}=VALUE) or declare it first with "
                                           f"<xacro:arg name=\"{m.group(1)}\" default=\"...\"/>")
        return known[m.group(1)]

    def get_include_files(self, filename_spec: str, symbols: dict) -> Iterator[str]:
        xacro, state = self.xacro, self.state
        spec = str(xacro.eval_text(filename_spec, symbols))
        current = Path(xacro.filestack[-1]) if xacro.filestack and xacro.filestack[-1] else state.top
        yield str(_include_path(spec, current, self.path, state))

    def parse(self, inp: Any, filename: str | None = None) -> Any:
        if inp is not None:
            return self.original["parse"](inp, filename)
        target = Path(filename)
        if not inside_folder(target, self.state.folder):  # pragma: no cover - get_include_files checked it
            raise MechanismFileError(self.path, f"xacro:include {quote(str(filename), 60)} is outside the file's "
                                                "folder")
        text, root = _read_file(target, self.path, self.state)
        _check_tree(root, target, self.state, follow=False)
        return _dom(text, target)

    def eval_all(self, node: MinidomElement, macros: dict, symbols: dict) -> Any:
        state = self.state
        child = node.firstChild
        while child is not None:
            if child.nodeType == child.ELEMENT_NODE and child.tagName == "xacro:insert_block":
                block = _block_named(child.getAttribute("name"), symbols)
                if block is not None:
                    state.copied += _block_size(block, symbols, frozenset({id(block)}), {})
                    if state.copied > LIMITS.elements:
                        raise MechanismFileError(self.path, f"xacro:insert_block copies expand to more than "
                                                            f"{LIMITS.elements} elements (refused: blocks inserted "
                                                            "in blocks double at each level)")
            child = child.nextSibling
        return self.original["eval_all"](node, macros, symbols)

    def eval_text(self, text: str, symbols: dict) -> Any:
        # xacro joins the values of a text's ${...} and $(...) outside the evaluator: bound them here
        # (a property "${s}${s}" of a property "${s}${s}" of ... doubles at each level)
        result = self.original["eval_text"](text, symbols)
        if isinstance(result, str) and len(result) > max(MAX_STRING, len(text)):  # grown by substitution
            raise self.xacro.XacroException(f"refused: a text of more than {MAX_STRING} characters (properties "
                                            "joining copies of each other?)")
        return result

    def reqd_attrs(self, tag: MinidomElement, names: list[str]) -> Any:
        # xacro's xmlutils raises RuntimeError for a missing attribute: the file's mistake, not a bug
        try:
            return self.original["reqd_attrs"](tag, names)
        except RuntimeError as exc:
            raise self.xacro.XacroException(str(exc)) from None

    def handle_macro_call(self, node: MinidomElement, macros: dict, symbols: dict) -> Any:
        xacro, state, path = self.xacro, self.state, self.path
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
        return self.original["handle_macro_call"](node, macros, symbols)


def _patched(xacro: ModuleType, state: _State, path: str | Path,
             evaluator: Callable[..., Any] | None = None) -> tuple[dict[str, Any], dict[str, Callable[..., Any]]]:
    """Replace xacro's evaluator (``evaluator``, default :func:`evaluate`), substitutions, includes and
    macro calls while expanding: (xacro's originals, their replacements)."""
    patches = _Patches(xacro, state, path, evaluator or evaluate)
    return patches.original, patches.replaced()


class XacroInternalError(RuntimeError):
    """An exception inside the xacro package that is not a ``XacroException`` (the file's
    mistakes are): a bug, reported as an internal error (exit 3), not as the file's fault."""


def _dom(text: str, path: Path):
    """A minidom document of checked text (defusedxml: no entities, no external references)."""
    # lazily: only xacro files need it; defusedxml.minidom.parseString's own parser, without the
    # import of defusedxml.minidom (its pulldom brings xml.sax, urllib, http, ssl and email: 18 ms)
    import defusedxml.expatbuilder

    try:
        return defusedxml.expatbuilder.parseString(text.encode("utf-8"), forbid_dtd=False, forbid_entities=True,
                                                   forbid_external=True)
    except (defusedxml.DefusedXmlException, ValueError) as exc:
        raise MechanismFileError(path, f"XML refused: {shorten(str(exc), 100)}") from None
    except Exception as exc:  # noqa: BLE001 - expat errors (checked before: should not happen)
        raise MechanismFileError(path, f"malformed XML: {shorten(_one_line(exc), 100)}") from None


def expand(path: Path, text: str, args: dict | None = None, root=None, warn: Callable | None=None, evaluator=None, read: list | None=None) -> str:
    """The URDF text of xacro file ``path`` (whose text is ``text``) with arguments
    ``args`` ({name: value}; see :func:`normalize_args`).  Raises MechanismFileError (the
    file's problem, one line) or UsageError (an argument the file does not declare).

    warn: callable receiving xacro's own warnings (default: dropped).
    evaluator: the interpreter of ``${...}`` (default :func:`evaluate`; files.xacro_batch expands a
    family for many designs at once with its own).
    read: a list, when given, that gets the path of each file the expansion read (the file's first)."""
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
        original, replaced = _patched(xacro, state, path, evaluator)
        saved_verbosity = xacro.verbosity
        try:
            for k, f in replaced.items():
                setattr(xacro, k, f)
            xacro.init_stacks(str(path))
            with contextlib.redirect_stderr(output), contextlib.redirect_stdout(output):
                xacro.process_doc(doc, mappings=dict(given), verbosity=0)
            result = doc.toxml()
        except MechanismFileError:
            raise
        except RecursionError:
            raise MechanismFileError(path, "xacro: macros or properties nested too deeply (recursive?)") from None
        except xacro.XacroException as exc:
            raise MechanismFileError(path, f"xacro: {shorten(_one_line(exc), 240)}") from None
        except Exception as exc:  # not a XacroException: not the file's mistake, a bug (xacro's or screwkin's)
            raise XacroInternalError(f"internal error in the xacro expansion of {path}: {type(exc).__name__}: "
                                     f"{shorten(_one_line(exc), 200)}") from exc
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
    if read is not None:
        read.extend(str(f) for f in state.files)
    if len(result) > LIMITS.file_bytes:
        raise MechanismFileError(path, f"the expanded URDF is over {LIMITS.file_bytes / 1e6:g} MB")
    return result

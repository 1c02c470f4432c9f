"""Size limits of the package (issue 42): at most 5 functions over 90 lines (nested functions and methods
count, each on its own) and no module over 600 lines, so that a function is a step of the work one reads at
once and a module a room one can hold.  Measured on the source by the ast, as a reader counts: from a
function's ``def`` line to its last line, a module's lines as ``wc -l`` counts them."""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "screwkin"
LONG_FUNCTION = 90  # lines
MOST_LONG_FUNCTIONS = 5
LONG_MODULE = 600  # lines


def long_functions(root: Path = PACKAGE, limit: int = LONG_FUNCTION) -> list[tuple[int, str]]:
    """(lines, "path:line name") of every function and method over ``limit`` lines, longest first."""
    out = []
    for path in sorted(root.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > limit:
                    out.append((n, f"{path.relative_to(root.parent)}:{node.lineno} {node.name}"))
    return sorted(out, reverse=True)


def long_modules(root: Path = PACKAGE, limit: int = LONG_MODULE) -> list[tuple[int, str]]:
    """(lines, path) of every module over ``limit`` lines, longest first."""
    out = []
    for path in sorted(root.rglob("*.py")):
        n = path.read_bytes().count(b"\n")
        if n > limit:
            out.append((n, str(path.relative_to(root.parent))))
    return sorted(out, reverse=True)


def test_the_counts_are_a_readers_counts(tmp_path):
    """The measure itself, on files whose numbers are known by construction: a function of 91 lines (def, a
    nested 2-line function and its blank line, 86 assignments, return), its nested function counted apart, a
    function of exactly 90 lines (not over), and a module of 601 lines (over) beside one of 600 (not)."""
    text = ("def long_one():\n    def inner():\n        return 1\n\n"
            + "".join(f"    x{k} = {k}\n" for k in range(86)) + "    return x0\n\n\n"
            + "def just_90():\n" + "".join(f"    y{k} = {k}\n" for k in range(88)) + "    return y0\n")
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    (pkg / "m.py").write_text(text)
    (pkg / "big.py").write_text("x = 1\n" * 601)
    (pkg / "fits.py").write_text("x = 1\n" * 600)
    every = {where.split()[-1]: n for n, where in long_functions(pkg, 0)}
    assert every == {"long_one": 91, "inner": 2, "just_90": 90}
    assert long_functions(pkg) == [(91, "pkg/m.py:1 long_one")]
    assert long_modules(pkg) == [(601, "pkg/big.py")]


def test_at_most_five_functions_over_90_lines():
    found = long_functions()
    assert len(found) <= MOST_LONG_FUNCTIONS, (
        f"{len(found)} functions over {LONG_FUNCTION} lines (at most {MOST_LONG_FUNCTIONS}): split them into "
        "named steps:\n" + "\n".join(f"  {n} lines  {where}" for n, where in found))


def test_no_module_over_600_lines():
    found = long_modules()
    assert not found, (f"modules over {LONG_MODULE} lines: split them by what they hold:\n"
                       + "\n".join(f"  {n} lines  {where}" for n, where in found))

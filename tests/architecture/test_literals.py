"""No new bare decision literal: a comparison (<, <=, >, >=) in screwkin/ whose operands hold a
float literal below 1e-3 (``abs(x) < 1e-7``, ``d > 1e-9 * scale``) is a threshold written
where it is used.  Decisions take a named field of ``screwkin.tolerances.Tolerances``;
division guards and display cut-offs a named module constant that says what it is
(``TINY = 1e-300  # division guard``).  ALLOWED counts what is left, file by file: a file may
go below its count (lower the count then), never above it."""

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "screwkin"
SMALL = 1e-3

#: file (relative to screwkin/) -> comparisons with a bare small literal still allowed there.
#: The first seven are being rewritten elsewhere (the solver and continuation) and keep their
#: counts of the day this test was written; synthesis/motion.py holds four thresholds of its
#: own (collinear precision points, Newton's step, two roots the same, a circle's spread);
#: loader.py (MJCF), view.py and draw.py are in other hands this round.
ALLOWED = {
    "model/kernel/closure.py": 0,
    "analysis/singularities/batch.py": 4,
    "model/kernel/stacks.py": 2,
    "model/kernel/compiled.py": 0,
    "analysis/motion/sweep.py": 0,
    "analysis/motion/singular_points.py": 1,
    "analysis/singularities/maps.py": 0,
    "analysis/design/workspace.py": 1,
    "analysis/design/workspace_grid.py": 1,
    "model/state.py": 0,
    "analysis/design/synthesis/motion.py": 4,
    "model/loader.py": 1,
    "present/draw.py": 3,
    "present/view.py": 2,
    "present/camera.py": 3,
}


def _small_literal(node) -> bool:
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        node = node.operand
    return (isinstance(node, ast.Constant) and isinstance(node.value, float)
            and not isinstance(node.value, bool) and 0 < abs(node.value) < SMALL)


def bare_comparisons(source: str) -> list:
    """Line numbers of the ordering comparisons whose operands hold a float literal below 1e-3."""
    out = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Compare) and any(isinstance(o, (ast.Lt, ast.LtE, ast.Gt, ast.GtE)) for o in node.ops):
            if any(_small_literal(n) for operand in (node.left, *node.comparators) for n in ast.walk(operand)):
                out.append(node.lineno)
    return sorted(out)


def test_the_scan_sees_what_it_should():
    assert bare_comparisons("ok = abs(x) < 1e-7") == [1]
    assert bare_comparisons("ok = d > 1e-9 * scale") == [1]
    assert bare_comparisons("ok = -1e-9 <= r <= 1 + 1e-9") == [1]
    assert bare_comparisons("ok = x < tol.stationary") == []
    assert bare_comparisons("ok = x < 0.5") == []  # not small
    assert bare_comparisons("ok = x == 1e-9") == []  # not an ordering
    assert bare_comparisons("y = max(x, 1e-300)") == []  # not a comparison


def test_no_new_bare_decision_literal():
    found = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        lines = bare_comparisons(path.read_text())
        if lines:
            found[path.relative_to(PACKAGE).as_posix()] = lines
    over = {f: lines for f, lines in found.items() if len(lines) > ALLOWED.get(f, 0)}
    assert not over, ("comparisons against a bare float literal below 1e-3 (name the threshold in "
                      "screwkin/tolerances.py's Tolerances, or a division guard as a module constant): "
                      + "; ".join(f"screwkin/{f} lines {lines} ({len(lines)} > {ALLOWED.get(f, 0)} allowed)"
                                  for f, lines in over.items()))


def test_the_allowlist_names_files_that_exist():
    assert all((PACKAGE / f).is_file() for f in ALLOWED)

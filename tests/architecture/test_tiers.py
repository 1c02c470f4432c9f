"""The test tiers say what they run (issue 33 item 7): the slow tier names tests that exist, and under
CI=true a test that skips for something CI installs (mujoco, viser, pyarrow, imageio-ffmpeg, check_urdf,
Chromium, ...) fails the run instead of skipping without a word (tests/conftest.py)."""

from __future__ import annotations

import ast
import functools
import os
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import CI_MODULES, CI_PROVIDES, ROOT, SLOW_TESTS

TESTS = Path(__file__).resolve().parents[1]
#: Skip reasons that are about the platform, not about what CI installs: these may skip anywhere.
PLATFORM = ("no named pipes here", "needs bash", "not a git checkout")


@functools.cache
def _defined(path: Path) -> set:
    """'name' of every top-level test function and 'Class::name' of every method in a class."""
    tree = ast.parse(path.read_text())
    out = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            out.add(node.name)
        elif isinstance(node, ast.ClassDef):
            out |= {f"{node.name}::{m.name}" for m in node.body if isinstance(m, (ast.FunctionDef, ast.AsyncFunctionDef))}
    return out


def test_every_slow_node_id_names_a_test_that_exists():
    """SLOW_TESTS is a list of node ids as strings: one left behind by a rename (or misspelt) would mark
    nothing and leave a slow test in the fast subset."""
    stale = []
    files = {path.name: path for path in TESTS.rglob("test_*.py")}
    for node in sorted(SLOW_TESTS):
        file, sep, name = node.split("[", 1)[0].partition("::")
        path = files.get(file)
        if not sep or path is None or name not in _defined(path):
            stale.append(node)
    assert not stale, f"SLOW_TESTS names tests that do not exist: {stale}"


def test_the_node_id_check_sees_a_stale_one():
    assert "test_every_slow_node_id_names_a_test_that_exists" in _defined(Path(__file__))
    assert "test_no_such_test" not in _defined(Path(__file__))


def _string(node) -> str | None:
    """The text of a string constant, or of an f-string's literal parts (None when neither)."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.JoinedStr):
        return "".join(v.value for v in node.values if isinstance(v, ast.Constant))
    return None


def _skips():
    """(file:line, what, text) of every skip in tests/: ('module', M) of pytest.importorskip(M) without
    a reason, ('reason', R) of importorskip's, pytest.skip's and skipif's reasons."""
    for path in sorted(TESTS.rglob("test_*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.Call) or not isinstance(node.func, ast.Attribute):
                continue
            where = f"{path.name}:{node.lineno}"
            reason = next((_string(k.value) for k in node.keywords if k.arg == "reason"), None)
            name = node.func.attr
            if name == "importorskip":
                yield (where, "reason", reason) if reason else (where, "module", _string(node.args[0]))
            elif name == "skip" and node.args:
                yield where, "reason", _string(node.args[0])
            elif name == "skipif":
                yield where, "reason", reason


def test_every_skip_is_one_ci_fails_on_or_a_platform_one():
    """A new skip for a missing module or program must be added to conftest.CI_PROVIDES (CI then fails
    when it happens) or be a platform's (PLATFORM): none skips quietly in CI."""
    loose = []
    seen = 0
    for where, what, text in _skips():
        seen += 1
        if what == "module":
            if not text or text.split(".")[0] not in CI_MODULES:
                loose.append(f"{where}: importorskip({text!r})")
        elif not text or not (any(p in text for p in CI_PROVIDES) or text in PLATFORM):
            loose.append(f"{where}: {text!r}")
    assert seen > 20
    assert not loose, f"skips CI would let pass without a word: {loose}"


def test_the_guard_names_what_the_issue_lists():
    for module in ("mujoco", "viser", "pyarrow", "imageio_ffmpeg"):
        assert f"could not import '{module}" in CI_PROVIDES and f"No module named '{module}" in CI_PROVIDES
    assert any("check_urdf" in p for p in CI_PROVIDES)


@pytest.mark.slow
def test_under_ci_a_missing_mujoco_viser_pyarrow_ffmpeg_or_check_urdf_fails_the_run(tmp_path):
    """The real test modules, run under CI=true with mujoco, viser, pyarrow and imageio_ffmpeg hidden
    (packages of those names that raise ModuleNotFoundError, first on the path) and no check_urdf on PATH:
    pytest exits 1 and names each skip.  test_mjcf.py skips at collection (importorskip at its top),
    the others inside a test.  Without CI the same run passes with the skips."""
    shadow = tmp_path / "shadow"
    for module in ("mujoco", "viser", "pyarrow", "imageio_ffmpeg"):
        (shadow / module).mkdir(parents=True)
        (shadow / module / "__init__.py").write_text(f"raise ModuleNotFoundError(\"No module named '{module}' (hidden)\")\n")
    tests = ["tests/files/test_mjcf.py", "tests/analysis/motion/test_sweep_stream.py::test_cli_parquet_has_the_csv_columns",
             "tests/present/test_view_server.py::test_sigterm_stops_the_interactive_view_too",
             "tests/present/test_draw_animate.py::test_an_mp4_through_imageio_ffmpeg",
             "tests/present/test_synthesis_drawing.py::test_check_urdf_parses_the_file_with_its_targets"]
    nothing = tmp_path / "bin"  # PATH: no check_urdf (the venv's bin has one too)
    nothing.mkdir()
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(shadow), str(ROOT)]), PATH=str(nothing))
    env.pop("CI", None)
    argv = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-rs", *tests]
    plain = subprocess.run(argv, cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
    assert plain.returncode == 0, plain.stdout[-3000:]
    ci = subprocess.run(argv, cwd=ROOT, env=dict(env, CI="true"), capture_output=True, text=True, timeout=600)
    assert ci.returncode == 1, ci.stdout[-3000:]
    summary = ci.stdout.split("skipped for something CI installs:", 1)[1]
    for module in ("mujoco", "viser", "pyarrow", "imageio_ffmpeg", "check_urdf"):
        assert module in summary, (module, summary)
    assert "test_mjcf.py" in summary  # the module skipped at collection

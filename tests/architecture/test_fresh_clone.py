"""The repository works on its own: a clone with nothing beside it runs the README's analysis
command and the tests that read bundled data (the corpus robots once lived in ../shared,
which only the team's checkouts have: 40 tests failed in a plain clone)."""

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.skipif(shutil.which("git") is None or not (ROOT / ".git").exists(),
                                reason="not a git checkout")


@pytest.fixture(scope="module")
def clone(tmp_path_factory):
    where = tmp_path_factory.mktemp("alone") / "screwkin"
    subprocess.run(["git", "clone", "--quiet", str(ROOT), str(where)], check=True, timeout=120)
    return where


def run(clone, *args, timeout=300):
    env = dict(os.environ, PYTHONPATH=str(clone))  # the clone's package, not the installed one
    return subprocess.run([sys.executable, *args], cwd=clone, env=env, capture_output=True, text=True,
                          timeout=timeout)


def test_nothing_reaches_outside_the_repository(clone):
    for path in clone.rglob("*.py"):
        if path.name == Path(__file__).name:
            continue  # (this file names what it looks for)
        text = path.read_text(errors="replace")
        assert "../shared" not in text and '"shared" / "corpus"' not in text, path


def test_the_readme_analysis_command_runs_in_the_clone(clone):
    readme = (clone / "README.md").read_text()
    commands = re.findall(r"^    (.+)$", readme, flags=re.M)[:2]
    install, tests = commands
    assert "pip install" in install and "screwkin " in install and tests.strip().endswith("python -m pytest -q")
    assert tests.strip() in (clone / ".ci" / "run").read_text().splitlines()  # CI runs exactly that command
    analysis = install.split("&&", 1)[1].split()
    assert analysis[0] == "screwkin"
    p = run(clone, "-c", "import screwkin, sys; print(screwkin.__file__)")
    assert Path(p.stdout.strip()).resolve().is_relative_to(clone.resolve()), p.stdout + p.stderr
    p = run(clone, "-m", "screwkin", *analysis[1:])
    assert p.returncode == 0, p.stderr
    assert "mobility M" in p.stdout and "3T" in p.stdout


def test_tests_on_bundled_data_pass_in_the_clone(clone):
    p = run(clone, "-m", "pytest", "-q", "-p", "no:cacheprovider", "tests/analysis/test_robots.py",
            "tests/files/test_corpus.py", "tests/analysis/position/test_as_written.py", "-x")
    assert p.returncode == 0, p.stdout[-3000:] + p.stderr[-2000:]
    assert re.search(r"\d+ passed", p.stdout)

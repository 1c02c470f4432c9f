"""ruff and mypy, configured in pyproject.toml, pass on the package: a plain `pytest` runs ruff (under a
second), the whole run (CI's, .ci/run) runs mypy too."""
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _run(*command: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", *command], cwd=ROOT, capture_output=True, text=True)


def test_ruff_is_clean():
    done = _run("ruff", "check", "--no-cache", "screwkin")
    assert done.returncode == 0, done.stdout + done.stderr


@pytest.mark.slow
def test_mypy_is_clean():
    done = _run("mypy")  # files, options and the untyped libraries: [tool.mypy] in pyproject.toml
    assert done.returncode == 0, done.stdout + done.stderr

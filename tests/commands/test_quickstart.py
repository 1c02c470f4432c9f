"""The README's quick start ("Your first four-bar") runs as written, in a folder of its own, and
answers what the README says it does: M = 1 and the rocker angles of the law of cosines."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]


def quickstart() -> str:
    readme = (ROOT / "README.md").read_text()
    section = readme.split("## Your first four-bar", 1)[1]
    return re.search(r"```bash\n(.*?)```", section, re.S).group(1)


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("bash") is None, reason="needs bash")
def test_quickstart_runs_verbatim(tmp_path):
    script = quickstart()
    assert script.startswith("cat > fourbar.urdf <<'EOF'") and "screwkin solve" in script
    bindir = tmp_path / "bin"  # `screwkin` is this interpreter's screwkin, from this checkout
    bindir.mkdir()
    (bindir / "screwkin").write_text(f'#!/bin/sh\nexec "{sys.executable}" -m screwkin "$@"\n')
    (bindir / "screwkin").chmod(0o755)
    work = tmp_path / "work"
    work.mkdir()
    env = dict(os.environ, PATH=f"{bindir}{os.pathsep}{os.environ['PATH']}",
               PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    p = subprocess.run(["bash", "-e", "-c", script], cwd=work, env=env, capture_output=True, text=True,
                       timeout=600)
    assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-2000:]
    out = p.stdout
    assert re.search(r"mobility M\D+1\b", out), out[:2000]
    # the rocker's absolute angle at a 30 deg crank, both modes, by the law of cosines
    a, b, c, d = 0.04, 0.12, 0.08, 0.10
    A, D = a * np.array([np.cos(np.radians(30)), np.sin(np.radians(30))]), np.array([d, 0.0])
    z = np.linalg.norm(A - D)
    gamma = np.arccos((c * c + z * z - b * b) / (2 * c * z))
    towards_a = np.arctan2(*(A - D)[::-1])
    for t4 in (towards_a - gamma, towards_a + gamma):
        shown = f"{np.degrees(np.mod(t4 + np.pi, 2 * np.pi) - np.pi):.6g}"
        assert re.search(rf"rocker\s+{re.escape(shown)}\s", out), shown
    for name in ("sweep.png", "fourbar.svg", "fourbar.html"):
        assert (work / name).stat().st_size > 1000, name
    assert "Grashof crank-rocker" in out and re.search(r"\nP\s+coupler\s", out)


def test_a_loop_that_cannot_close_is_explained_in_its_lengths(tmp_path, capsys):
    """The quick start's four-bar with its ground at 0.25 m: 0.25 > 0.04 + 0.12 + 0.08 = 0.24, said so."""
    from screwkin.cli import main

    text = quickstart().split("<<'EOF'\n", 1)[1].split("\nEOF\n", 1)[0]
    assert '<origin xyz="0.10 0 0"/>' in text
    path = tmp_path / "long.urdf"
    path.write_text(text.replace('<origin xyz="0.10 0 0"/>', '<origin xyz="0.25 0 0"/>'))
    assert main(["mobility", str(path)]) == 1
    err = capsys.readouterr().err
    assert "loop B cannot close, ground 0.25 m > " in err and f"= {0.04 + 0.12 + 0.08:.6g} m" in err
    for link in ("crank", "coupler", "rocker"):
        assert link in err.split("ground 0.25 m > ", 1)[1].split("=", 1)[0]


def test_closable_bundled_mechanisms_have_no_closure_obstacle():
    from screwkin import load

    for name in ("fourbar_crank_rocker", "fourbar_non_grashof", "five_bar", "watt_sixbar", "stephenson_sixbar",
                 "planar_3rrr", "bennett", "rssr"):
        assert load(str(ROOT / "robots" / f"{name}.urdf")).closure_obstacle() is None, name

"""The scripts in examples/ run and print what they promise."""

import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def run(name, *args):
    p = subprocess.run([sys.executable, str(EXAMPLES / name), *args], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    return p.stdout


def test_corpus_survey():
    out = run("corpus_survey.py")
    assert "cassie_like" in out and "not assembled" in out  # kangaroo_like's welds cannot close


def test_menagerie_survey(tmp_path):
    """menagerie_survey.py on a checkout of two of the test's own MJCF forms (Menagerie itself is not
    shipped): each loads, its mobility is MuJoCo's, its export simulates, and the tally says so."""
    pytest.importorskip("mujoco")
    import shutil
    data = Path(__file__).resolve().parent / "data" / "mjcf"
    for folder, name in (("gripper", "gripper_4bar_tendon.xml"), ("leg", "leg_ref_loop.xml")):
        (tmp_path / folder).mkdir()
        shutil.copy(data / name, tmp_path / folder / name)
    out = run("menagerie_survey.py", str(tmp_path))
    assert "gripper/gripper_4bar_tendon.xml" in out and "leg/leg_ref_loop.xml" in out
    assert ("tally: models 2, mujoco_loads 2, screwkin_loads 2, mobility_equal 2, positions_1e-9 2, "
            "export_simulates 2") in out


def test_overconstrained():
    out = run("overconstrained.py")
    assert "bennett: Kutzbach -2" in out and "screw-theory mobility 1" in out


def test_fourbar_motion():
    out = run("fourbar_motion.py", "72")
    assert "2 assembly modes" in out and "Grashof crank-rocker" in out
    assert out.count("rocker stops") == 2


@pytest.mark.parametrize("script", sorted(p.name for p in EXAMPLES.glob("*.py")))
def test_every_example_is_tested(script):
    assert script in Path(__file__).read_text()


def test_readme_python_blocks_run(monkeypatch, capsys):
    """The Python API page's examples (docs/reference/python.md: the README's Python section until issue
    45) run as written, from the repository root, and print what their comments say."""
    import re

    root = EXAMPLES.parent
    blocks = re.findall(r"```python\n(.*?)```", (root / "docs" / "reference" / "python.md").read_text(), re.S)
    assert len(blocks) >= 3
    monkeypatch.chdir(root)
    namespace = {}
    for code in blocks:
        exec(compile(code, "docs/reference/python.md", "exec"), namespace)
    out = capsys.readouterr().out
    assert out.splitlines()[0] == "9 6 3T"  # mobility, idle DOFs, output motion of the Delta
    assert namespace["d"].shape == (100000,) and namespace["J"].shape == (100000, 6, 6)
    assert namespace["q"].shape == (namespace["mech"].model.nq,)


def test_stewart_motor_loop():
    import re

    out = run("stewart_motor_loop.py", "100")
    worst = [float(x) for x in re.findall(r"worst closure residual ([0-9.e+-]+)", out)]
    assert worst and max(worst) < 1e-10
    same = re.search(r"same path to ([0-9.e+-]+) m", out)
    assert same is None or float(same.group(1)) < 1e-12

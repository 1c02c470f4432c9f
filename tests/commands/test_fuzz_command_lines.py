"""Fuzzing, round 5 (issue 43): generated files and command lines of the kinds round 4 found defects in.

Each mutant is a pure function of its index: a planted ``OUT.partial`` (a symbolic link to a victim, a hard
link to it, or a file of the user's own) beside an output; an output named as a file the model was read
from (an MJCF include, a xacro include, a mesh, the sidecar); MJCF includes nested to a random depth; a
fixed tendon's coefficient from the hostile values; a picture option given a file name of any suffix;
``--mode K`` where the inputs leave a continuum; a planar loop of many joints folded flat.  Checked for
each: the contract (exit 0, 1 or 2, never 3, one error line, no traceback), no hang (a bound of seconds),
no silent acceptance (what must be refused is refused, what is answered is right: Gruebler's count of a
loop), and no file changed or made that the command line does not name as an output.

SCREWKIN_FUZZ_SCALE=N runs N times as many (a campaign); the first FAST of them run in the fast subset.
"""

from __future__ import annotations

import functools
import hashlib
import json
import math
import os
import random
import re

import pytest

from conftest import ROBOTS, no_hang
from test_fuzz import HOSTILE, SCALE, check_contract
from test_security import folded_loop

SEED = 20261206
MUTANTS = 84 * SCALE
FAST = 21
FOURBAR = ROBOTS / "fourbar_crank_rocker.urdf"
FIVE = ROBOTS / "five_bar.urdf"
SWEEP = ["--input", "crank_joint", "--from", "0", "--to", "1", "--steps", "3"]

#: Commands that write one output file (its option, its usual name) from the four-bar.
WRITERS = [
    (["sweep", "{f}", *SWEEP, "--csv"], "o.csv"),
    (["sweep", "{f}", *SWEEP, "--chunk", "2", "--csv"], "o.csv"),
    (["sweep", "{f}", *SWEEP, "--plot"], "o.png"),
    (["sweep", "{f}", *SWEEP, "--chunk", "2", "--parquet"], "o.parquet"),
    (["export", "{f}", "--urdf"], "o.urdf"),
    (["export", "{f}", "--mjcf"], "o.xml"),
    (["draw", "{f}", "--svg"], "o.svg"),
    (["view", "{f}", "--html"], "o.html"),
    (["report", "{f}", "--no-view", "--steps", "24", "--html"], "o.html"),
    (["dynamics", "{f}", "--input", "crank_joint", "--speed", "10rpm", "--steps", "4", "--csv"], "o.csv"),
]
#: Picture options and the suffixes each writes (None: matplotlib's formats, PGF aside).
PICTURES = [
    (["sweep", "{f}", *SWEEP, "--plot"], None),
    (["dynamics", "{f}", "--input", "crank_joint", "--speed", "10rpm", "--steps", "4", "--plot"], None),
    (["draw", "{f}", "--png"], {".png"}),
    (["draw", "{f}", "--svg"], {".svg"}),
    (["draw", "{f}", "--animate", "--from", "0", "--to", "1", "--steps", "2", "--fps", "5"], {".gif", ".mp4"}),
    (["map", str(FIVE), "--x", "motor1=0:1:3", "--y", "motor2=0:1:3", "--png"], None),
]
SUFFIXES = [".xml", ".parquet", ".csv", ".pgf", ".png", ".PNG", ".svg", ".jpg", ".pdf", ".gif", ".mp4", "", ".tar.gz",
            ".png.xml", ".svgz", ".eps", ".html", ".urdf", ". png", ".webp"]
MATPLOTLIB = {".avif", ".eps", ".gif", ".jpeg", ".jpg", ".pdf", ".png", ".ps", ".raw", ".rgba", ".svg", ".svgz", ".tif",
              ".tiff", ".webp"}
#: Continua: (file, its arguments leaving free degrees of freedom, the commands tried).
CONTINUA = [(str(FIVE), ["--actuated", "motor1", "--set", "motor1=10deg"]),
            (str(FIVE), ["--actuated", "motor2", "--set", "motor2=-20deg"])]
CONTINUUM_COMMANDS = [["mobility"], ["screws"], ["draw", "--png", "d.png"], ["export", "--urdf", "e.urdf"],
                      ["statics"], ["singularities"]]


def _mjcf_files(rng, tmp_path, depth_files=None, frames=None):
    """A two-link MJCF model whose bodies come through includes: (main file, the files it includes)."""
    body = ('<body name="b1"><joint name="j1" type="hinge" axis="0 0 1"/><geom type="capsule" size="0.02" '
            'fromto="0 0 0 0.1 0 0"/><body name="b2" pos="0.1 0 0"><joint name="j2" type="hinge" axis="0 0 1"/>'
            '<geom type="capsule" size="0.02" fromto="0 0 0 0.1 0 0"/></body></body>')
    files = depth_files or rng.randint(1, 3)
    frames = frames if frames is not None else rng.randint(0, 3)
    (tmp_path / "parts").mkdir(exist_ok=True)
    included = []
    for i in range(files):
        inner = f'<include file="parts/f{i + 1}.xml"/>' if i < files - 1 else body
        path = tmp_path / "parts" / f"f{i}.xml"
        path.write_text("<mujoco>" + "<frame>" * frames + inner + "</frame>" * frames + "</mujoco>\n")
        included.append(path)
    main = tmp_path / "main.xml"
    main.write_text('<mujoco><worldbody><include file="parts/f0.xml"/></worldbody></mujoco>\n')
    return main, included


def _fill(template, model):
    return [str(model) if a == "{f}" else a for a in template]


@functools.cache
def kind_of(i: int) -> str:
    return ["partial", "included", "depth", "tendon", "picture", "continuum", "loop"][i % 7]


def _scenario(i, tmp_path):
    """(argv, the outputs it names, what must hold: 'refused-usage', 'refused-file', 'any', or a callable
    on (code, out, err)), with the files of the scenario made in tmp_path."""
    rng = random.Random(SEED * 31 + i)
    kind = kind_of(i)
    model = tmp_path / "fourbar.urdf"
    model.write_text(FOURBAR.read_text())
    if kind == "partial":
        template, name = rng.choice(WRITERS)
        out = tmp_path / name
        planted = tmp_path / (name + ".partial")
        victim = rng.choice([tmp_path / "victim.txt", model])
        if victim != model:
            victim.write_text("the victim\n")
        how = rng.choice(["symlink", "hardlink", "own file", "dangling symlink"])
        if how == "symlink":
            planted.symlink_to(victim)
        elif how == "hardlink":
            os.link(victim, planted)
        elif how == "own file":
            planted.write_text("my own notes\n")
        else:
            planted.symlink_to(tmp_path / "nowhere" / "x")
        return [*_fill(template, model), str(out)], {out}, "any"
    if kind == "included":
        main, included = _mjcf_files(rng, tmp_path)
        target = rng.choice(included)
        option = rng.choice([["sweep", str(main), "--input", "j1", "--from", "0", "--to", "1", "--steps", "2", "--csv"],
                             ["export", str(main), "--urdf"], ["export", str(main), "--mjcf"],
                             ["draw", str(main), "--svg"]])
        if option[-1] == "--svg":  # (a picture name: the file read is refused first, whatever its suffix)
            new = target.with_suffix(".svg")
            for p in [main, *included]:
                p.write_text(p.read_text().replace(target.name, new.name))
            target.rename(new)
            target = new
        return [*option, str(target)], set(), "refused-usage"
    if kind == "depth":
        files, frames = rng.randint(1, 14), rng.choice([1, 10, 30, 48, 49, 50, 90, 97])
        main, included = _mjcf_files(rng, tmp_path, files, frames)
        depth = 2 + files * frames + 2  # <mujoco><worldbody>, the frames, <body><body>, and their joints/geoms
        expect = "refused-file" if depth + 1 > 100 else "any"
        return ["info", str(main), "--json"], set(), expect
    if kind == "tendon":
        coef = rng.choice(HOSTILE + ["1", "-2.5", "0.5", "1e9", "1e10", "0"])
        main, _ = _mjcf_files(rng, tmp_path, 1, 0)
        main.write_text(main.read_text().replace(
            "</mujoco>", f'<tendon><fixed name="t"><joint joint="j1" coef="{coef}"/><joint joint="j2" coef="1"/>'
                         '</fixed></tendon><actuator><motor tendon="t"/></actuator></mujoco>'))
        return ["info", str(main), "--json"], set(), "any"
    if kind == "picture":
        template, formats = rng.choice(PICTURES)
        suffix = rng.choice(SUFFIXES)
        out = tmp_path / ("o" + suffix)
        allowed = (MATPLOTLIB if formats is None else formats)
        ok = suffix.lower() in allowed or (formats is None and suffix == "")
        argv = _fill(template, model)
        k = argv.index("--animate") + 1 if "--animate" in argv else len(argv)
        argv = argv[:k] + [str(out)] + argv[k:]
        return argv, {out}, (lambda code, o, e, ok=ok: code == 0 if ok else code == 2)
    if kind == "continuum":
        path, given = rng.choice(CONTINUA)
        command = rng.choice(CONTINUUM_COMMANDS)
        mode = rng.choice([None, 1, 2, 17, 25])
        argv = [command[0], path, *given, *[str(tmp_path / a) if "." in a else a for a in command[1:]]]
        outputs = {tmp_path / a for a in command[1:] if "." in a}
        if mode is not None:
            argv += ["--mode", str(mode)]

        def check(code, out, err, mode=mode):
            assert not re.search(r"assembly mode \d+ of", err), err  # samples are not numbered as modes
            if mode is not None and mode > 1:
                return code == 2 and "continuum" in err
            return code in (0, 1) and (code == 1 or "continuum" in err)
        return argv, outputs, check
    n = rng.choice([6, 8, 10, 12, 16, 20, 24])
    path = tmp_path / f"loop{n}.urdf"
    path.write_text(folded_loop(n, length=rng.choice([0.01, 0.1, 1.0])))
    return ["mobility", str(path), "--json"], set(), (lambda code, out, err, n=n: code == 0
                                                     and json.loads(out)["mobility"] == n - 3)


def _snapshot(folder):
    """Every entry under ``folder``: path -> ('link', target) or ('file', sha256 of its bytes)."""
    out = {}
    for root, dirs, files in os.walk(folder):
        for name in dirs + files:
            p = os.path.join(root, name)
            if os.path.islink(p):
                out[p] = ("link", os.readlink(p))
            elif os.path.isfile(p):
                with open(p, "rb") as f:
                    out[p] = ("file", hashlib.sha256(f.read()).hexdigest())
    return out


@pytest.mark.parametrize("i", [pytest.param(i, marks=() if i < FAST else pytest.mark.slow) for i in range(MUTANTS)],
                         ids=lambda i: f"r5-{i:03d}-{kind_of(i)}")
def test_round5_mutant(i, tmp_path, capfd, monkeypatch):
    monkeypatch.chdir(tmp_path)
    argv, outputs, expect = _scenario(i, tmp_path)
    before = _snapshot(tmp_path)
    with no_hang(180):
        code, out, err = check_contract(argv, capfd, [tmp_path, ROBOTS], full=True)
    where = f"r5-{i} {' '.join(argv)[:300]}:\n{err[-1500:]}"
    if expect == "refused-usage":
        assert code == 2, where
    elif expect == "refused-file":
        assert code == 1 and "nested deeper than" in err, where
    elif callable(expect):
        assert expect(code, out, err), where
    after = _snapshot(tmp_path)
    named = {str(p) for p in outputs}
    changed = sorted(p for p in set(before) | set(after) if before.get(p) != after.get(p) and p not in named)
    assert not changed, f"{where}\nfiles changed or made that no output names: {changed}"
    if code != 0:  # a refused command writes nothing
        assert not [p for p in named if os.path.lexists(p) and p not in before], where


def test_the_generators_cover_every_kind():
    kinds = {kind_of(i) for i in range(FAST)}
    assert kinds == {"partial", "included", "depth", "tendon", "picture", "continuum", "loop"}
    assert math.isfinite(float(len(WRITERS)))

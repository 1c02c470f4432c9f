"""Hostile inputs (issue 22, round 2): mesh files outside the robot's folder are never read into an
output, and link and joint names written as HTML, spreadsheet formulas, commas or line breaks stay
inert text in every output format.

The canary is a file of random bytes (a valid OBJ with a random token) placed beside the robot's
folder; every route a mesh URI can take out of the folder points at it.  What is asserted is
traceable outside the code under test: the canary's own bytes and their base64, the names as
written here, and csv.reader's reading of each CSV."""

from __future__ import annotations

import base64
import csv
import io
import json
import os
import secrets
from pathlib import Path
from xml.sax.saxutils import quoteattr

import pytest

import screwkin
from conftest import fourbar, planar_3r, screwkin_cli

SCRIPT = "<script>alert(1)</script>"
IMG = "<img src=x onerror=alert(1)>"
FORMULA = "=cmd|' /C calc'!A0,x\ny"  # a formula, a comma and a line break in one joint name
MINUS = "-a,b\nc"  # starts like a formula (and is not a number)
AT = "@x,y\nz"
RAW_HTML = ("<script>alert", "<img src=x")  # a name's tags as tags; escaped (&lt;img ...) they are text


def _attr(name: str) -> str:
    return quoteattr(name).replace("\n", "&#10;").replace("\r", "&#13;")


def _rename(text: str, names: dict) -> str:
    for old, new in names.items():
        text = text.replace(f'"{old}"', _attr(new))
    return text


def _mesh(uri):
    return f'<visual><geometry><mesh filename="{uri}"/></geometry></visual>'


ROUTES = ["../outside/canary.obj",  # relative, up and out
          "package://outside/canary.obj",  # package:// resolved against the file's parent
          "package:///outside/canary.obj",  # package:// with no package, against the parent
          "package://robot/../outside/canary.obj",  # out of the robot's own package
          "link.obj",  # a symlink in the folder to the canary
          "sub/../../outside/canary.obj"]


@pytest.fixture
def hostile(tmp_path):
    """(robot file, 2R arm file, canary bytes, output folder)."""
    outside = tmp_path / "outside"
    outside.mkdir()
    token = secrets.token_hex(24)
    canary = (f"# {token}\nv 0 0 0\nv 0.01 0 0\nv 0 0.01 0\nf 1 2 3\n# {token}\n").encode()
    (outside / "canary.obj").write_bytes(canary)
    robot = tmp_path / "robot"
    (robot / "sub").mkdir(parents=True)
    os.symlink(outside / "canary.obj", robot / "link.obj")
    uris = ROUTES + [(outside / "canary.obj").as_uri()]  # file:///...
    text = fourbar().replace('<link name="ground">', '<link name="ground">' + "".join(_mesh(u) for u in uris))
    text = _rename(text, {"coupler": SCRIPT, "rocker": MINUS, "coupler_joint": IMG, "rocker_joint": FORMULA})
    (robot / "robot.urdf").write_text(text)
    arm = _rename(planar_3r(), {"j1": MINUS, "j2": AT, "l2": SCRIPT, "l3": IMG})
    arm = arm.replace('<link name="base">', '<link name="base">' + _mesh("../outside/canary.obj"))
    (robot / "arm.urdf").write_text(arm)
    out = tmp_path / "out"
    out.mkdir()
    return robot / "robot.urdf", robot / "arm.urdf", canary, out


def _no_canary(data: bytes, canary: bytes, what):
    token = canary.split(b"\n")[0][2:]
    for needle in (canary, token, base64.b64encode(canary), base64.b64encode(canary[:30])):
        assert needle not in data, f"{what}: the canary's bytes are in the output"


def _outputs(out: Path):
    return {p: p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()}


def test_meshes_outside_the_folder_are_refused_with_a_warning_each(hostile):
    path, _, canary, out = hostile
    seen = []
    mech = screwkin.load(path, warn=seen.append)
    outside = [w for w in seen if "outside the robot's folder" in w]
    assert outside and all("mesh " in w for w in outside)
    named = " ".join(seen)
    assert "'../outside/canary.obj'" in named and "'package://outside/canary.obj'" in named
    assert "more mesh file(s) outside" in named  # 7 routes: 3 named, the rest counted
    assert mech.spec.links  # the file still loads


@pytest.mark.slow  # eleven commands in processes of their own: about 15 s
def test_no_output_holds_the_canary_or_raw_html_names(hostile):
    path, arm, canary, out = hostile
    runs = {
        "view": ["view", path, "--html", out / "view.html"],
        "report_html": ["report", path, "--html", out / "report.html"],
        "report_md": ["report", path, "--md", out / "report.md"],
        "draw": ["draw", path, "--svg", out / "draw.svg"],
        "sweep_csv": ["sweep", path, "--input", "crank_joint", "--from", "1.4", "--to", "1.7", "--steps", "4",
                      "--csv", out / "sweep.csv", "--json"],
        "solve": ["solve", path, "--set", "crank_joint=1.5", "--json"],
        "info": ["info", path, "--json"],
        "mobility": ["mobility", path, "--json"],
        "map": ["map", arm, f"--x={MINUS}=0:1:3", f"--y={AT}=0.5:1:3", "--csv", out / "map.csv"],
        "workspace": ["workspace", arm, "--output", IMG, "--resolution", "50mm", "--csv", out / "ws.csv"],
        "scan": ["scan", arm, "--output", IMG, "--samples", "20", "--csv", out / "scan.csv"],
    }
    stdout = {}
    for name, args in runs.items():
        r = screwkin_cli(*map(str, args))
        code, so, se = r.returncode, r.stdout, r.stderr
        assert code == 0, f"{name}: {se[-400:]}"
        assert "outside the robot's folder" in se, f"{name}: no warning for the outside meshes"
        _no_canary(so.encode(), canary, name)
        stdout[name] = so
    for name in ("sweep_csv", "solve", "info", "mobility"):
        json.loads(stdout[name])  # the JSON outputs parse
    assert SCRIPT in json.dumps(json.loads(stdout["info"]), ensure_ascii=False)  # names intact in JSON
    files = _outputs(out)
    assert {"view.html", "report.html", "report.md", "draw.svg", "sweep.csv", "map.csv", "ws.csv",
            "scan.csv"} <= {p.name for p in files}
    for p, data in files.items():
        _no_canary(data, canary, p.name)
        if p.suffix in (".html", ".svg", ".md"):
            text = data.decode("utf-8", "replace")
            for raw in RAW_HTML:
                assert raw not in text, f"{p.name}: {raw!r} from a name is in the output raw"
            # onerror= only inside the escaped name, never as an attribute of a tag
            escaped = text.count("&lt;img src=x onerror=alert") + text.count("\\u003cimg src=x onerror=alert")
            assert text.count("onerror=alert") == escaped, p.name
    md = files[out / "report.md"].decode()
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in md  # the name is there, as text
    for line in md.splitlines():  # every table row has as many cells as its header
        if line.startswith("|"):
            assert line.replace("\\|", "").count("|") >= 3


def _rows(path: Path):
    rows = list(csv.reader(io.StringIO(path.read_text(), newline="")))
    assert rows and len({len(r) for r in rows}) == 1, f"{path.name}: rows of different lengths"
    return rows


def test_csv_quotes_names_and_neutralises_formulas(hostile):
    path, arm, _, out = hostile
    assert screwkin_cli("sweep", str(path), "--input", "crank_joint", "--from", "1.4", "--to", "1.7", "--steps",
                        "4", "--csv", str(out / "sweep.csv")).returncode == 0
    head, *body = _rows(out / "sweep.csv")
    assert "'" + FORMULA in head and IMG in head and f"d_{FORMULA}" in head
    assert not any(c.startswith(("=", "+", "@")) for c in head)
    assert len(body) == 5 and all(isinstance(float(c), float) for r in body for c in r)  # numbers stay numbers
    assert any(c.startswith("-") for r in body for c in r)  # a negative number is written as it is
    assert screwkin_cli("map", str(arm), f"--x={MINUS}=0:1:3", f"--y={AT}=0.5:1:3",
                        "--csv", str(out / "map.csv")).returncode == 0
    head, *body = _rows(out / "map.csv")
    assert head == ["'" + MINUS, "'" + AT, "log10_sigma_min", "kind"] and len(body) == 9
    assert screwkin_cli("scan", str(arm), "--output", IMG, "--samples", "20",
                        "--csv", str(out / "scan.csv")).returncode == 0
    head, *body = _rows(out / "scan.csv")
    assert head == ["'" + MINUS, "'" + AT, "j3", "sigma_ratio"] and len(body) == 20
    assert screwkin_cli("workspace", str(arm), "--output", IMG, "--resolution", "50mm",
                        "--csv", str(out / "ws.csv")).returncode == 0
    head, *body = _rows(out / "ws.csv")
    assert head[-3:] == ["'" + MINUS, "'" + AT, "j3"] and body


def test_package_dirs_and_the_files_own_package_are_still_read(tmp_path, capsys):
    """The confinement does not refuse what the user allowed: a --package-dir anywhere, and the
    package the file sits in (pkg/urdf/robot.urdf reading package://pkg/meshes/m.obj); but
    package://pkg/../x does not leave a --package-dir package."""
    obj = "v 0 0 0\nv 0.01 0 0\nv 0 0.01 0\nf 1 2 3\n"
    own = tmp_path / "ws" / "my_robot"
    (own / "urdf").mkdir(parents=True)
    (own / "meshes").mkdir()
    (own / "meshes" / "m.obj").write_text(obj)
    far = tmp_path / "elsewhere" / "pkgs"
    (far / "other" / "meshes").mkdir(parents=True)
    (far / "other" / "meshes" / "o.obj").write_text(obj)
    (tmp_path / "elsewhere" / "secret.obj").write_text(obj)
    text = fourbar().replace('<link name="ground">', '<link name="ground">' + _mesh("package://my_robot/meshes/m.obj")
                             + _mesh("package://other/meshes/o.obj"))
    (own / "urdf" / "robot.urdf").write_text(text)
    seen = []
    screwkin.load(own / "urdf" / "robot.urdf", warn=seen.append, package_dirs=[far])
    assert seen == []
    bad = text.replace("package://other/meshes/o.obj", "package://other/../../secret.obj")
    (own / "urdf" / "robot.urdf").write_text(bad)
    screwkin.load(own / "urdf" / "robot.urdf", warn=seen.append, package_dirs=[far])
    assert len(seen) == 1 and "'package://other/../../secret.obj' is outside" in seen[0]

"""Hostile inputs (issue 22, round 2): mesh files outside the robot's folder are never read into an
output, and link and joint names written as HTML, spreadsheet formulas, commas or line breaks stay
inert text in every output format.

The canary is a file of random bytes (a valid OBJ with a random token) placed beside the robot's
folder; every route a mesh URI can take out of the folder points at it.  What is asserted is
traceable outside the code under test: the canary's own bytes and their base64, the names as
written here, and csv.reader's reading of each CSV.

Hostile inputs, round 4 (issue 43): a planted ``OUT.partial`` link, outputs onto a model's included
files, includes nested past the depth limit together, a fixed tendon's invalid coefficient, a plot whose
suffix names no picture format, samples of a continuum numbered as assembly modes, a long loop folded
flat.  Each is refused with one line (exit 1 for a file, 2 for a command line), or answered with a line
saying what was done; a file not named as an output is never changed."""

from __future__ import annotations

import base64
import csv
import io
import json
import math
import os
import re
import secrets
import subprocess
import sys
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np
import pytest

import screwkin
from conftest import ROBOTS, fourbar, no_hang, planar_3r, screwkin_cli
from screwkin.cli import main

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
        "map": ["map", arm, f"--x={MINUS}=0:1:3", f"--y={AT}=0.5:1:3", "--set", "j3=0", "--csv", out / "map.csv"],
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
    assert screwkin_cli("map", str(arm), f"--x={MINUS}=0:1:3", f"--y={AT}=0.5:1:3", "--set", "j3=0",
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


# ------------------------------------------------------------------ every output fails one way (issue 33)
FOURBAR_FILE = Path(__file__).resolve().parents[2] / "robots" / "fourbar_crank_rocker.urdf"
FIVE_FILE = Path(__file__).resolve().parents[2] / "robots" / "five_bar.urdf"
_SWEEP = ["sweep", FOURBAR_FILE, "--input", "crank_joint", "--from", "0", "--to", "360deg", "--steps", "200"]
_DYN = ["dynamics", FOURBAR_FILE, "--input", "crank_joint", "--speed", "60rpm", "--steps", "36"]
_STUDY = {"file": str(FOURBAR_FILE.parent / "fourbar.urdf.xacro"), "args": {"ground": 0.1},
          "parameters": {"crank": {"values": [0.02, 0.03, 0.04]}}, "metrics": ["mobility", "grashof"]}
#: Every output a command writes (but the headless-Chromium pictures, view --png and workspace
#: --cloud-png, which take the same route: present/outfile.write_output): id -> argv with {o} for the path.
OUTPUTS = {
    "sweep-csv": [*_SWEEP, "--csv", "{o}.csv"],
    "sweep-streamed-csv": [*_SWEEP[:-1], "40000", "--chunk", "5000", "--csv", "{o}.csv"],
    "sweep-parquet": [*_SWEEP[:-1], "40000", "--chunk", "5000", "--parquet", "{o}.parquet"],
    "sweep-plot": [*_SWEEP, "--plot", "{o}.png"],
    "dynamics-csv": [*_DYN, "--csv", "{o}.csv"],
    "dynamics-plot": [*_DYN, "--plot", "{o}.png"],
    "map-csv": ["map", FIVE_FILE, "--x", "motor1=0:0.4:4", "--y", "motor2=1.5:2:4", "--csv", "{o}.csv"],
    "map-png": ["map", FIVE_FILE, "--x", "motor1=0:0.4:4", "--y", "motor2=1.5:2:4", "--png", "{o}.png"],
    "scan-csv": ["scan", FOURBAR_FILE.parent / "arm_6r.urdf", "--output", "flange", "--samples", "500", "--csv",
                 "{o}.csv"],
    "workspace-csv": ["workspace", FIVE_FILE, "--output", "tip", "--resolution", "50mm", "--csv", "{o}.csv"],
    "workspace-png": ["workspace", FIVE_FILE, "--output", "tip", "--resolution", "50mm", "--png", "{o}.png"],
    "workspace-html": ["workspace", FIVE_FILE, "--output", "tip", "--resolution", "50mm", "--html", "{o}.html"],
    "draw-png": ["draw", FOURBAR_FILE, "--png", "{o}.png"],
    "draw-svg": ["draw", FOURBAR_FILE, "--svg", "{o}.svg"],
    "draw-gif": ["draw", FOURBAR_FILE, "--animate", "{o}.gif", "--input", "crank_joint", "--from", "0", "--to",
                 "90deg", "--steps", "3"],
    "view-html": ["view", FOURBAR_FILE, "--html", "{o}.html"],
    "report-html": ["report", FOURBAR_FILE, "--no-view", "--html", "{o}.html"],
    "report-md": ["report", FOURBAR_FILE, "--no-view", "--md", "{o}.md"],
    "export-mjcf": ["export", FOURBAR_FILE, "--mjcf", "{o}.xml"],
    "export-urdf": ["export", FOURBAR_FILE, "--urdf", "{o}.urdf"],
    "study-table": ["study", "{spec}", "--workers", "0", "-o", "{o}.csv"],
    "synthesize-urdf": ["synthesize", "path", "--points", "0,0; 0.05,0.02; 0.1,0.05; 0.12,0.1; 0.08,0.12",
                        "--starts", "2", "-o", "{o}.urdf"],
}


def _argv(template, out, spec):
    return [str(a).replace("{o}", str(out)).replace("{spec}", str(spec)) for a in template]


@pytest.fixture
def study_spec(tmp_path):
    import yaml

    path = tmp_path / "study.yaml"
    path.write_text(yaml.safe_dump(_STUDY))
    return path


def _single_error(err: str) -> str:
    """The one error line (a study's summary line and warnings may come before it), last on stderr."""
    lines = err.strip().splitlines()
    errors = [line for line in lines if line.startswith("screwkin:")]
    assert errors and errors == lines[-1:] and "Traceback" not in err and "internal error" not in err, err
    return errors[0]


#: The outputs whose commands take a second or more (a document, a scene, a workspace): the slow tier.
HEAVY = {"report-html", "report-md", "view-html", "workspace-csv", "workspace-png", "workspace-html", "draw-gif",
         "map-png"}


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow) if n in HEAVY else n for n in sorted(OUTPUTS)])
def test_a_full_disk_is_exit_1_naming_the_path_and_the_reason(name, study_spec, tmp_path, capsys):
    """/dev/full takes the opening and fails the writing (ENOSPC): the work is done, the file cannot take it
    (reached through a link named with the suffix the command wants).  Before, sweep --csv, dynamics --csv
    and view --html were exit 3 and --plot exit 0 having written nothing; export, report and draw said it
    with exit 2."""
    from screwkin.cli import main

    full = tmp_path / "full"
    argv = _argv(OUTPUTS[name], full, study_spec)
    target = next(a for a in argv if a.startswith(str(full)))
    os.symlink("/dev/full", target)
    code = main(argv)
    line = _single_error(capsys.readouterr().err)
    assert code == 1 and line == f"screwkin: error: cannot write '{target}': No space left on device", line
    assert os.path.islink(target) and os.path.exists("/dev/full")  # neither the link nor the device is removed


@pytest.mark.parametrize("name", sorted(OUTPUTS))
def test_a_folder_that_takes_no_file_is_refused_before_the_work(name, study_spec, capsys):
    """/proc exists and is writable to root but makes no new file: passed the up-front check and failed
    after the work (exit 3).  Now a usage error naming the option, before any work."""
    from screwkin.cli import main

    argv = _argv(OUTPUTS[name], "/proc/screwkin-out", study_spec)
    code = main(argv)
    line = _single_error(capsys.readouterr().err)
    assert code == 2 and "/proc/screwkin-out" in line and "cannot write, no file can be made in '/proc'" in line, line
    assert not any(p.startswith("screwkin-out") for p in os.listdir("/proc"))


def _limited(nbytes):
    import resource

    def set_limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (nbytes, nbytes))

    return set_limit


def _past_the_size_limit(name, tmp_path, spec):
    """The output of ``name`` under a 300-byte file-size limit (RLIMIT_FSIZE, as ``ulimit -f``): the
    write fails with EFBIG once the file is at the limit.  Exit 1, "File too large", the partial file
    removed (nothing left at the path)."""
    out = tmp_path / "out" / "x"
    out.parent.mkdir()
    argv = _argv(OUTPUTS[name], out, spec)
    p = subprocess.run([sys.executable, "-m", "screwkin", *argv], capture_output=True, text=True, timeout=300,
                       preexec_fn=_limited(300))
    line = _single_error(p.stderr)
    assert p.returncode == 1 and "cannot write" in line and "File too large" in line, line
    assert line.endswith("(the partial file was removed)"), line
    assert not list(out.parent.iterdir()), list(out.parent.iterdir())


@pytest.mark.parametrize("name", ["sweep-streamed-csv", "sweep-parquet", "dynamics-csv", "export-mjcf"])
def test_past_a_file_size_limit_the_partial_file_is_removed_and_said(name, tmp_path, study_spec):
    _past_the_size_limit(name, tmp_path, study_spec)


@pytest.mark.slow  # every other output in a process of its own: about 40 s
@pytest.mark.parametrize("name", sorted(set(OUTPUTS) - {"sweep-streamed-csv", "sweep-parquet", "dynamics-csv",
                                                          "export-mjcf"}))
def test_past_a_file_size_limit_every_output(name, tmp_path, study_spec):
    _past_the_size_limit(name, tmp_path, study_spec)


@pytest.mark.slow  # about 3.8 s on 2 shared cores: out of the fast subset
def test_under_a_file_size_limit_the_compiled_kernels_stay_in_memory(tmp_path):
    """The RSSR's modes come from the homotopy, whose kernels numba compiles and caches on disk: under
    ``ulimit -f`` the cache file's write failed with EFBIG, exit 3 ("internal error ... File too
    large") on a solve that writes no file.  Now the kernels stay in memory there (an empty cache
    folder forces the write)."""
    root = Path(__file__).resolve().parents[2]
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba")}
    p = subprocess.run([sys.executable, "-m", "screwkin", "solve", str(root / "robots" / "rssr.urdf"),
                        "--set", "crank_joint=0.3"], capture_output=True, text=True, timeout=300,
                       preexec_fn=_limited(300), env=env)
    assert p.returncode == 0 and "rocker_joint" in p.stdout, p.stderr
    assert not (tmp_path / "numba").exists()


def test_a_folder_of_outputs_where_no_folder_can_be_made_is_refused_before_the_work(capsys):
    """synthesize chains -o /proc/chains was exit 3 (mkdir failed after the enumeration)."""
    from screwkin.cli import main

    code = main(["synthesize", "chains", "--links", "4", "--dof", "1", "-o", "/proc/screwkin-chains"])
    line = _single_error(capsys.readouterr().err)
    assert code == 2 and "cannot write, no folder can be made in '/proc'" in line, line


def test_a_killed_streamed_sweep_leaves_only_a_file_named_partial(tmp_path):
    """A process killed on the way (SIGKILL: no handler runs) cannot clean up: the streamed CSV is written as
    out.csv.<random>.partial and renamed only once whole, so out.csv never holds half a sweep.  (Found by the
    directed probes: a killed sweep left a partial out.csv.)  The kill waits for the partial file to hold
    rows, so a slow machine's start-up cannot end the run before the file exists (a CPU-time limit of one
    second did, on CI)."""
    import signal
    import time

    out = tmp_path / "out.csv"
    proc = subprocess.Popen([sys.executable, "-m", "screwkin", *_argv(OUTPUTS["sweep-streamed-csv"],
                                                                      tmp_path / "out", None)[:-4],
                             "--steps", "2000000", "--csv", str(out)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 240
        while time.monotonic() < deadline and proc.poll() is None:
            partial = list(tmp_path.glob("out.csv.*.partial"))
            if partial and partial[0].stat().st_size > 0:
                break
            time.sleep(0.05)
        assert proc.poll() is None, ("the sweep ended before it was killed", proc.returncode)
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        proc.stderr.close()
    assert proc.returncode == -signal.SIGKILL
    assert not out.exists() and len(list(tmp_path.glob("out.csv.*.partial"))) == 1


def test_a_failed_write_leaves_a_file_that_was_there_as_it_was(tmp_path):
    """The new file is made beside the old one and replaces it once whole: a full disk or a size limit
    leaves the old output untouched."""
    out = tmp_path / "out.csv"
    out.write_text("the old table\n")
    p = subprocess.run([sys.executable, "-m", "screwkin", *_argv(OUTPUTS["sweep-csv"], tmp_path / "out", None)],
                       capture_output=True, text=True, timeout=300, preexec_fn=_limited(300))
    assert p.returncode == 1 and "File too large (the partial file was removed)" in p.stderr
    assert out.read_text() == "the old table\n" and sorted(q.name for q in tmp_path.iterdir()) == ["out.csv"]


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no named pipes here")
def test_a_named_pipe_nothing_reads_is_an_error_not_a_wait(tmp_path, capsys):
    """Opening a named pipe for writing waits for a reader: with none, screwkin waited for ever.  Opened
    without waiting, a pipe nothing reads is exit 1 at once; one that is read takes the output."""
    from screwkin.cli import main

    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    with no_hang(60):
        code = main(_argv(OUTPUTS["sweep-csv"], tmp_path / "pipe", None))
    line = _single_error(capsys.readouterr().err)
    assert code == 1 and line.endswith("cannot write '" + str(fifo) + "': a named pipe that nothing reads"), line
    reader = subprocess.Popen(["cat", str(fifo)], stdout=subprocess.PIPE)
    p = subprocess.run([sys.executable, "-m", "screwkin", *_argv(OUTPUTS["sweep-csv"], tmp_path / "pipe", None)],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0 and reader.communicate(timeout=60)[0].decode().count("\n") == 202  # header + 201 rows


# ---------------------------------------------------------------- folded in from test_hostile_round4.py
FOURBAR = ROBOTS / "fourbar_crank_rocker.urdf"
FIVE_BAR = ROBOTS / "five_bar.urdf"
SWEEP = ["--input", "crank_joint", "--from", "0", "--to", "1", "--steps", "3"]


def _one_line_error(err: str) -> str:
    """The one error line (the `note:` lines a command says as it goes may come before it)."""
    lines = [ln for ln in err.strip().splitlines() if not ln.startswith("note: ")]
    assert len(lines) == 1 and lines[0].startswith("screwkin: error: ") and "Traceback" not in err, err
    return lines[0]


@pytest.fixture
def model(tmp_path):
    path = tmp_path / "x.urdf"
    path.write_text(FOURBAR.read_text())
    return path


# ------------------------------------------------------------------ a planted OUT.partial
def test_a_planted_partial_link_is_not_followed(model, tmp_path, capsys):
    """sweep --csv o.csv with o.csv.partial -> victim wrote the sweep into the victim and left o.csv a link
    to it, exit 0.  The partial file is a fresh name made new (O_EXCL | O_NOFOLLOW): the victim and the
    link stay as they were, o.csv is a regular file holding the sweep."""
    victim = tmp_path / "victim.txt"
    victim.write_text("the victim's own text\n")
    (tmp_path / "o.csv.partial").symlink_to(victim)
    assert main(["sweep", str(model), *SWEEP, "--csv", str(tmp_path / "o.csv")]) == 0
    capsys.readouterr()
    assert victim.read_text() == "the victim's own text\n"
    assert (tmp_path / "o.csv.partial").is_symlink() and (tmp_path / "o.csv.partial").resolve() == victim
    out = tmp_path / "o.csv"
    assert not out.is_symlink() and out.read_text().startswith("step,crank_joint_input,")
    assert len(out.read_text().splitlines()) == 1 + 4  # the header and the 4 configurations of 3 steps


def test_a_planted_partial_link_to_the_model_leaves_the_model(model, tmp_path, capsys):
    """report --html o.html with o.html.partial -> the model replaced the URDF with HTML."""
    before = model.read_bytes()
    (tmp_path / "o.html.partial").symlink_to(model)
    assert main(["report", str(model), "--no-view", "--html", str(tmp_path / "o.html")]) == 0
    capsys.readouterr()
    assert model.read_bytes() == before
    assert (tmp_path / "o.html").read_text().lstrip().lower().startswith("<!doctype html")


def test_a_planted_hard_link_is_not_reused(tmp_path):
    """A hard link under the old partial name was opened and truncated: the file it shares is kept."""
    from screwkin.present.outfile import write_output

    victim = tmp_path / "victim.txt"
    victim.write_text("kept\n")
    (tmp_path / "o.txt.partial").hardlink_to(victim)
    write_output(tmp_path / "o.txt", "the output\n")
    assert victim.read_text() == "kept\n" and (tmp_path / "o.txt").read_text() == "the output\n"


def test_a_users_own_file_named_partial_is_left_alone(model, tmp_path, capsys):
    """A file of the user's named OUT.partial was overwritten and renamed away (so lost)."""
    mine = tmp_path / "o.csv.partial"
    mine.write_text("mine\n")
    assert main(["sweep", str(model), *SWEEP, "--csv", str(tmp_path / "o.csv")]) == 0
    capsys.readouterr()
    assert mine.read_text() == "mine\n"
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".partial") and p != mine]  # none left behind


def test_a_streamed_parquet_sweep_does_not_follow_a_planted_link(model, tmp_path, capsys):
    pytest.importorskip("pyarrow")
    victim = tmp_path / "victim.txt"
    victim.write_text("v\n")
    (tmp_path / "o.parquet.partial").symlink_to(victim)
    assert main(["sweep", str(model), *SWEEP, "--chunk", "2", "--parquet", str(tmp_path / "o.parquet")]) == 0
    capsys.readouterr()
    import pyarrow.parquet as pq

    assert victim.read_text() == "v\n" and pq.read_table(tmp_path / "o.parquet").num_rows == 4


def test_the_output_file_keeps_the_permissions_a_new_file_gets(tmp_path):
    """Made through os.open(..., 0o666) as open(..., "w") makes a file: the umask decides, as before."""
    import os

    from screwkin.present.outfile import write_output

    old = os.umask(0o022)
    try:
        write_output(tmp_path / "o.txt", "x")
    finally:
        os.umask(old)
    assert (tmp_path / "o.txt").stat().st_mode & 0o777 == 0o644
    os.chmod(tmp_path / "o.txt", 0o600)  # a private output replaced stays private
    write_output(tmp_path / "o.txt", "y")
    assert (tmp_path / "o.txt").stat().st_mode & 0o777 == 0o600 and (tmp_path / "o.txt").read_text() == "y"


# ------------------------------------------------------------------ outputs onto files the model was read from
def _mjcf_with_include(folder):
    (folder / "parts").mkdir()
    (folder / "main.xml").write_text('<mujoco><worldbody><include file="parts/geom_bodies.xml"/></worldbody></mujoco>\n')
    (folder / "parts" / "geom_bodies.xml").write_text(
        '<mujoco><body name="b1"><joint name="j1" type="hinge" axis="0 0 1"/>'
        '<geom type="capsule" size="0.02" fromto="0 0 0 0.1 0 0"/></body></mujoco>\n')
    return folder / "main.xml", folder / "parts" / "geom_bodies.xml"


def test_an_output_onto_an_mjcf_include_is_refused(tmp_path, capsys):
    """sweep --csv parts/geom_bodies.xml overwrote the file the model <include>s."""
    main_file, part = _mjcf_with_include(tmp_path)
    before = part.read_bytes()
    code = main(["sweep", str(main_file), "--input", "j1", "--from", "0", "--to", "1", "--steps", "2", "--csv",
                 str(part)])
    line = _one_line_error(capsys.readouterr().err)
    assert code == 2 and "a file the model was read from" in line and "geom_bodies.xml" in line, line
    assert part.read_bytes() == before


def test_an_output_onto_a_xacro_include_is_refused(tmp_path, capsys):
    """export --urdf inc.xacro overwrote the file the xacro file includes."""
    (tmp_path / "top.urdf.xacro").write_text(
        '<robot name="t" xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:include filename="inc.xacro"/>'
        '<link name="base"/><xacro:arm/></robot>\n')
    inc = tmp_path / "inc.xacro"
    inc.write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:macro name="arm">'
        '<link name="l1"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" '
        'iyz="0"/></inertial></link><joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>'
        '<axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint></xacro:macro></robot>\n')
    before = inc.read_bytes()
    code = main(["export", str(tmp_path / "top.urdf.xacro"), "--urdf", str(inc)])
    line = _one_line_error(capsys.readouterr().err)
    assert code == 2 and "a file the model was read from" in line, line
    assert inc.read_bytes() == before


def test_an_output_onto_a_mesh_is_refused(model, tmp_path, capsys):
    mesh = tmp_path / "part.stl"
    mesh.write_text("solid s\nendsolid s\n")
    text = model.read_text().replace('<link name="crank">', '<link name="crank"><visual><geometry>'
                                     '<mesh filename="part.stl"/></geometry></visual>', 1)
    model.write_text(text)
    code = main(["sweep", str(model), *SWEEP, "--csv", str(mesh)])
    line = _one_line_error(capsys.readouterr().err)
    assert code == 2 and "a file the model was read from" in line and mesh.read_text() == "solid s\nendsolid s\n"


def test_the_description_lists_the_files_read(tmp_path):
    import screwkin

    main_file, part = _mjcf_with_include(tmp_path)
    spec = screwkin.load(main_file, warn=lambda w: None).spec
    assert [str(main_file), str(part.resolve())] == spec.files_read


# ------------------------------------------------------------------ MJCF includes nested past the limit together
def test_nested_includes_are_bounded_over_the_whole_model(tmp_path, capsys):
    """12 included files of 90 nested <frame>s each: each under the depth limit of 100, together 1,080
    deep: RecursionError, exit 3.  The limit holds over the model with its includes in place."""
    (tmp_path / "main.xml").write_text(
        '<mujoco><worldbody><body name="b"><joint name="j" type="hinge"/><geom size="0.1"/></body>'
        '<include file="f0.xml"/></worldbody></mujoco>')
    for i in range(12):
        inner = f'<include file="f{i + 1}.xml"/>' if i < 11 else '<geom size="0.1"/>'
        (tmp_path / f"f{i}.xml").write_text("<mujoco>" + "<frame>" * 90 + inner + "</frame>" * 90 + "</mujoco>")
    with no_hang(60):
        code = main(["info", str(tmp_path / "main.xml")])
    line = _one_line_error(capsys.readouterr().err)
    assert code == 1 and "nested deeper than 100" in line and "includes" in line, line


def test_includes_nested_within_the_limit_are_read(tmp_path, capsys):
    """Two files of 40 nested frames each (83 deep with the main file's elements): read."""
    (tmp_path / "main.xml").write_text(
        '<mujoco><worldbody><include file="f0.xml"/></worldbody></mujoco>')
    body = '<body name="b"><joint name="j" type="hinge"/><geom size="0.1"/></body>'
    (tmp_path / "f0.xml").write_text("<mujoco>" + "<frame>" * 40 + '<include file="f1.xml"/>' + "</frame>" * 40
                                     + "</mujoco>")
    (tmp_path / "f1.xml").write_text("<mujoco>" + "<frame>" * 40 + body + "</frame>" * 40 + "</mujoco>")
    assert main(["info", str(tmp_path / "main.xml"), "--json"]) == 0
    assert [j["name"] for j in json.loads(capsys.readouterr().out)["joints"]] == ["j"]


# ------------------------------------------------------------------ a fixed tendon's invalid coefficient
@pytest.mark.parametrize("coef, why", [("1e308", "not a plausible value"), ("nan", "NaN or infinite"),
                                       ("inf", "NaN or infinite"), ("abc", "is not 1 number")])
def test_a_fixed_tendons_invalid_coef_is_one_line(tmp_path, capsys, coef, why):
    """TypeError: float() argument must be ... 'NoneType', exit 3: the coefficient was refused, then read."""
    path = tmp_path / "t.xml"
    path.write_text(
        '<mujoco><worldbody><body name="b1"><joint name="j1" type="hinge" axis="0 0 1"/>'
        '<geom type="capsule" size="0.02" fromto="0 0 0 0.1 0 0"/><body name="b2" pos="0.1 0 0">'
        '<joint name="j2" type="hinge" axis="0 0 1"/><geom type="capsule" size="0.02" fromto="0 0 0 0.1 0 0"/>'
        f'</body></body></worldbody><tendon><fixed name="t"><joint joint="j1" coef="{coef}"/>'
        '<joint joint="j2" coef="1"/></fixed></tendon><actuator><motor tendon="t"/></actuator></mujoco>')
    code = main(["info", str(path)])
    line = _one_line_error(capsys.readouterr().err)
    assert code == 1 and str(path) in line and "tendon 't' joint 'j1' coef" in line and why in line, line


# ------------------------------------------------------------------ a picture file that is not a picture
@pytest.mark.parametrize("name", ["o.xml", "o.parquet", "o.csv", "o.pgf"])
def test_a_plot_whose_suffix_is_no_picture_format_is_a_usage_error(model, tmp_path, capsys, name):
    """sweep --plot o.xml: matplotlib's "Format 'xml' is not supported", exit 3; .pgf needs a TeX system
    (xelatex), exit 3 without one.  A usage error naming the formats, before any work."""
    code = main(["sweep", str(model), *SWEEP, "--plot", str(tmp_path / name)])
    line = _one_line_error(capsys.readouterr().err)
    assert code == 2 and "--plot expects a file name ending in" in line and ".png" in line and ".svg" in line, line
    assert not (tmp_path / name).exists()


@pytest.mark.parametrize("argv, option", [
    (["map", str(FIVE_BAR), "--x", "motor1=0:1:3", "--y", "motor2=0:1:3", "--png", "{o}"], "--png"),
    (["dynamics", str(FOURBAR), "--input", "crank_joint", "--speed", "10rpm", "--steps", "4", "--plot", "{o}"], "--plot"),
    (["draw", str(FOURBAR), "--png", "{o}"], "--png"),
    (["draw", str(FOURBAR), "--svg", "{o}"], "--svg"),
    (["draw", str(FOURBAR), "--animate", "{o}"], "--animate"),
    (["view", str(FOURBAR), "--png", "{o}"], "--png"),
    (["workspace", str(FOURBAR), "--png", "{o}"], "--png"),
])
def test_every_picture_option_goes_through_the_one_check(tmp_path, capsys, argv, option):
    code = main([a.replace("{o}", str(tmp_path / "o.xml")) for a in argv])
    line = _one_line_error(capsys.readouterr().err)
    assert code == 2 and f"{option} expects a file name ending in" in line, line


@pytest.mark.parametrize("suffix, magic", [(".jpg", b"\xff\xd8\xff"), (".gif", b"GIF8"), (".tif", (b"II*\x00", b"MM\x00*")),
                                           (".webp", b"RIFF"), (".png", b"\x89PNG")])
def test_a_titled_figure_in_a_format_without_metadata_is_written(tmp_path, capsys, suffix, magic):
    """Found by the round-5 campaign: map --png o.jpg said "metadata not supported for format 'jpeg'", exit 3
    (the figure's title is given as metadata, which matplotlib writes into PNG, PDF, SVG and PostScript only).
    The file is the format its suffix names: its magic bytes."""
    out = tmp_path / ("o" + suffix)
    assert main(["map", str(FIVE_BAR), "--x", "motor1=0:1:3", "--y", "motor2=0:1:3", "--png", str(out)]) == 0
    capsys.readouterr()
    assert out.read_bytes().startswith(magic if isinstance(magic, bytes) else tuple(magic))


def test_a_pdf_map_says_nothing_but_what_it_wrote(tmp_path, capfd):
    """Found by the round-5 campaign: map --png o.pdf printed matplotlib's UserWarning "Unknown infodict keyword:
    'Description'" (PDF calls it Subject).  The PDF's Subject is the map's description."""
    out = tmp_path / "o.pdf"
    assert main(["map", str(FIVE_BAR), "--x", "motor1=0:1:3", "--y", "motor2=0:1:3", "--png", str(out)]) == 0
    assert "Warning" not in capfd.readouterr().err
    assert out.read_bytes().startswith(b"%PDF") and b"/Subject" in out.read_bytes()


def test_what_matplotlib_says_as_it_writes_is_a_warning_line(model, tmp_path, capfd):
    """sweep --plot o.eps printed matplotlib's own log line, "The PostScript backend does not support transparency;
    ...", bare on stderr: now a warning line naming the file, as every warning is said."""
    out = tmp_path / "o.eps"
    assert main(["sweep", str(model), *SWEEP, "--plot", str(out)]) == 0
    err = capfd.readouterr().err
    assert all(line.startswith(("note: ", "warning: ")) for line in err.splitlines()), err
    assert f"warning: {out}: matplotlib: The PostScript backend does not support transparency" in err
    assert out.read_bytes().startswith(b"%!PS-Adobe")


def test_the_formats_a_plot_takes_are_matplotlibs(tmp_path):
    """The list named is matplotlib's own (less PGF, which needs a TeX system), and each of them is written."""
    pytest.importorskip("matplotlib")
    from matplotlib.backend_bases import FigureCanvasBase

    from screwkin.commands._options import _matplotlib_formats

    assert set(_matplotlib_formats()) == {"." + k for k in FigureCanvasBase.get_supported_filetypes()} - {".pgf"}


# ------------------------------------------------------------------ samples of a continuum are not modes
FIVE_ONE_INPUT = [str(FIVE_BAR), "--actuated", "motor1", "--set", "motor1=10deg"]


def test_mode_on_a_continuum_is_a_usage_error(capsys):
    """The five-bar has mobility 2 (Gruebler: 3 (5 - 1) - 2 * 5 = 2); one input leaves 1 degree of freedom free
    (solve says "continuum"), and mobility --mode 17 said "assembly mode 17 of 25" of 25 random samples."""
    code = main(["mobility", *FIVE_ONE_INPUT, "--mode", "17"])
    line = _one_line_error(capsys.readouterr().err)
    assert code == 2 and "1 degree of freedom free (a continuum)" in line and "17 of" not in line, line


@pytest.mark.parametrize("command", [["mobility"], ["draw", "--png", "{d}/d.png"], ["screws"]])
def test_a_continuum_is_said_everywhere_and_its_sample_called_a_sample(tmp_path, capsys, command):
    argv = [command[0], *FIVE_ONE_INPUT, *[a.replace("{d}", str(tmp_path)) for a in command[1:]]]
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert not re.search(r"assembly mode \d+ of", err), err
    assert "1 degree of freedom free (a continuum): the configuration used is one sample of it" in err, err


def test_the_json_says_continuum_not_mode(capsys):
    assert main(["mobility", *FIVE_ONE_INPUT, "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["continuum"] == {"free_dofs": 1} and "mode" not in d


def test_solve_and_the_commands_say_it_in_the_same_words(capsys):
    assert main(["solve", *FIVE_ONE_INPUT]) == 0
    out = capsys.readouterr().out
    assert "these inputs leave 1 degree of freedom free (a continuum): they are samples of it" in out
    assert "assembly modes found" not in out  # (solve said "25 assembly modes found" of the samples)


# ------------------------------------------------------------------ a long loop folded flat
def folded_loop(n: int, length: float = 0.1) -> str:
    """n revolute joints in one planar loop of n links of one length (the ground one of them), folded flat
    (every link on the x axis, each turned back by pi at its joint; n even)."""
    inert = '<inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>'
    out = [f'<robot name="loop{n}">'] + [f'<link name="l{k}">{inert}</link>' for k in range(n)]
    for k in range(1, n):
        xyz, yaw = ("0 0 0", 0) if k == 1 else (f"{length} 0 0", math.pi)
        out.append(f'<joint name="j{k}" type="revolute"><parent link="l{k - 1}"/><child link="l{k}"/>'
                   f'<origin xyz="{xyz}" rpy="0 0 {yaw!r}"/><axis xyz="0 0 1"/>'
                   '<limit lower="-6.3" upper="6.3" effort="1" velocity="1"/></joint>')
    out.append(f'<loop_joint name="jc" type="revolute"><link1 link="l{n - 1}" xyz="{length} 0 0" rpy="0 0 0"/>'
               f'<link2 link="l0" xyz="{length} 0 0" rpy="0 0 {math.pi!r}"/><axis xyz="0 0 1"/></loop_joint>')
    return "\n".join(out + ["</robot>"]) + "\n"


def test_the_next_residual_is_affine_in_the_last_coefficient(tmp_path):
    """The lookahead of the local analysis took, for each of the kernel's d directions, a whole new residual
    (d residuals per order: most of the 38-57 s of a 40-joint loop folded flat); the residual is affine in
    the last coefficient pushed, so its change is computed at once (Series.residual_change).  Checked here
    against the differences of whole residuals, direction by direction, order by order."""
    import screwkin
    from screwkin.analysis.loop_series import Series, loop_system

    path = tmp_path / "loop.urdf"
    path.write_text(folded_loop(12))
    mech = screwkin.load(path, warn=lambda w: None)
    q = mech.assemble().q
    system = loop_system(mech, q)
    A = system.jacobian
    _, s, vt = np.linalg.svd(A)
    N = vt[int(np.sum(s > 1e-9 * s[0])):].T  # ker A: the first-order motions
    rng = np.random.default_rng(7)
    series = Series(system, N @ rng.standard_normal(N.shape[1]))
    for k in range(1, 5):
        series.residual()
        base = rng.standard_normal(system.columns)
        pushed = series.copy()
        pushed.push(base)
        r0 = pushed.residual()
        change = pushed.residual_change(N)
        for j in range(N.shape[1]):
            other = series.copy()
            other.push(base + N[:, j])
            assert np.allclose(other.residual() - r0, change[:, j], rtol=1e-12, atol=1e-12)
        series.push(base)


@pytest.mark.slow
def test_a_40_joint_loop_folded_flat_is_analysed(tmp_path, capsys):
    """38-57 s before, with nothing said.  Gruebler's count of a planar loop of n links and n revolute joints,
    3 (n - 1) - 2 n = n - 3: 37 for 40; the folded configuration is a singular point (the rank of the loop
    drops by one: every joint on one line)."""
    path = tmp_path / "loop40.urdf"
    path.write_text(folded_loop(40))
    with no_hang(300):
        assert main(["mobility", str(path), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["mobility"] == 37

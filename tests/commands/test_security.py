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
import subprocess
import sys
from pathlib import Path
from xml.sax.saxutils import quoteattr

import pytest

import screwkin
from conftest import fourbar, no_hang, planar_3r, screwkin_cli

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
FOURBAR_FILE = Path(__file__).resolve().parents[1] / "robots" / "fourbar_crank_rocker.urdf"
FIVE_FILE = Path(__file__).resolve().parents[1] / "robots" / "five_bar.urdf"
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
    root = Path(__file__).resolve().parents[1]
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

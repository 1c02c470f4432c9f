"""Hostile inputs, round 4 (issue 43): a planted ``OUT.partial`` link, outputs onto a model's included
files, includes nested past the depth limit together, a fixed tendon's invalid coefficient, a plot whose
suffix names no picture format, samples of a continuum numbered as assembly modes, a long loop folded
flat.  Each is refused with one line (exit 1 for a file, 2 for a command line), or answered with a line
saying what was done; a file not named as an output is never changed."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from conftest import ROBOTS, no_hang
from screwkin.cli import main

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

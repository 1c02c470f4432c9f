"""screwkin draw: skeleton diagrams, kinematic chains and singular configurations, checked by
counting the symbols of the figures (their gids), the pixels of the files written, the
structural counts of `screwkin info`, and the dead-centre inputs of the four-bar and the
slider-crank in closed form (law of cosines)."""

import json
from collections import Counter

import numpy as np
import pytest
from conftest import ROBOTS

import screwkin
from screwkin.analysis.course.figures import singular_configurations
from screwkin.analysis.course.skeleton import kinematic_chain, letters, skeleton
from screwkin.cli import main
from screwkin.present.draw import draw_chain, draw_mechanism

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")
import matplotlib.image
import matplotlib.pyplot as plt

FOURBAR = str(ROBOTS / "fourbar_crank_rocker.urdf")
SLIDER = str(ROBOTS / "slider_crank_offset.urdf")


def gids(fig):
    """Counter of the gid kinds ('link', 'joint', ...) of every artist in the figure, and the labels."""
    kinds, labels = Counter(), Counter()
    for a in fig.findobj():
        g = a.get_gid()
        if g:
            kinds[g.split(":")[0]] += 1
        lab = a.get_label() if hasattr(a, "get_label") else ""
        if isinstance(lab, str) and lab and not lab.startswith("_"):
            labels[lab] += 1
    return kinds, labels


def assembled(path):
    mech = screwkin.load(path)
    return mech, mech.generic_configurations()[0].q


def ink(path):
    """Share of the pixels that are not white, and the pixels' standard deviation."""
    img = matplotlib.image.imread(path)[..., :3]
    return float(np.mean(img.min(axis=2) < 0.95)), float(img.std())


def test_letters():
    assert [letters(k) for k in (0, 1, 25, 26, 27)] == ["A", "B", "Z", "AA", "AB"]


def test_fourbar_numbered_and_lettered_as_textbooks_do():
    mech, q = assembled(FOURBAR)
    skel = skeleton(mech, q)
    assert [(lk.number, lk.name, lk.shape) for lk in skel.links] == [
        (1, "ground", "ground"), (2, "crank", "bar"), (3, "coupler", "bar"), (4, "rocker", "bar")]
    assert [(j.letter, j.name) for j in skel.joints] == [
        ("A", "crank_joint"), ("B", "coupler_joint"), ("C", "coupler_rocker"), ("D", "rocker_joint")]
    assert skel.joint("A").input and skel.joint("C").cut
    # the file's geometry: crank 0.04 at 60 deg from the pivot at the origin, rocker pivot at (0.1, 0)
    np.testing.assert_allclose(skel.joint("B").point, (0.02, 0.04 * np.sin(np.radians(60))), atol=1e-12)
    np.testing.assert_allclose(skel.joint("D").point, (0.1, 0.0), atol=1e-12)
    fig = draw_mechanism(skel, angles=True)
    kinds, labels = gids(fig)
    assert kinds["link"] == 4 and kinds["joint"] == 4  # 4 links, 4 pins (the loop joint C too)
    assert labels["pin"] == 4 and labels["bar"] == 3
    assert kinds["ground"] == 2 and kinds["hatch"] == 2  # two ground pivots, hatched
    assert kinds["input"] == 1
    assert kinds["angle"] == 3  # theta 2, 3, 4 (the ground's is 0)
    texts = [t.get_text() for t in fig.findobj(matplotlib.text.Text) if (t.get_gid() or "").startswith("anglelabel")]
    assert "θ2 = 60.0°" in texts
    plt.close(fig)


def test_fourbar_png_and_svg_from_the_command_line(tmp_path, capsys):
    png, svg = tmp_path / "four.png", tmp_path / "four.svg"
    assert main(["draw", FOURBAR, "--png", str(png), "--svg", str(svg)]) == 0
    out = capsys.readouterr().out
    assert f"wrote {png}" in out and f"wrote {svg}" in out
    share, std = ink(png)
    empty = tmp_path / "empty.png"
    fig = plt.figure(figsize=(10, 6.4))
    fig.savefig(empty, dpi=110)
    plt.close(fig)
    share0, std0 = ink(empty)
    assert share0 == 0.0 and std0 == 0.0
    assert 0.005 < share < 0.5 and std > 0.02  # something drawn, most of it white background
    assert matplotlib.image.imread(png).shape[:2] == matplotlib.image.imread(empty).shape[:2]
    text = svg.read_text()
    assert "<svg" in text and text.count('id="joint:') == 4 and text.count('id="link:') == 4


def test_title_names_the_file_and_the_inputs(tmp_path, capsys):
    png = tmp_path / "f.png"
    assert main(["draw", FOURBAR, "--png", str(png), "--set", "crank_joint=30deg", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["files"] == [str(png)]
    assert d["inputs"]["crank_joint"] == pytest.approx(np.radians(30))
    mech, _ = assembled(FOURBAR)
    q = screwkin.PositionSolver(mech).solve({"crank_joint": np.radians(30)}).solutions[0].q
    skel = skeleton(mech, q)
    # the crank turned 30 deg from its 60 deg: B at 90 deg
    np.testing.assert_allclose(skel.joint("B").point, (0.0, 0.04), atol=1e-9)


def test_slider_crank_has_a_slider_block_on_a_hatched_guide():
    mech, q = assembled(SLIDER)
    skel = skeleton(mech, q)
    assert [lk.shape for lk in skel.links] == ["ground", "bar", "bar", "block"]
    d = skel.joint("D")
    assert d.type == "prismatic" and d.direction == pytest.approx((1.0, 0.0))
    fig = draw_mechanism(skel)
    kinds, labels = gids(fig)
    assert kinds["link"] == 4 and kinds["joint"] == 4
    assert labels["slider"] == 1 and labels["guide"] == 1 and labels["pin"] == 3
    assert kinds["hatch"] == 2  # the crank's pivot and the guide
    plt.close(fig)


@pytest.mark.parametrize("name", ["fourbar_crank_rocker", "slider_crank_offset", "watt_sixbar", "cam_followers",
                                  "planar_3rpr", "gear_train_idler"])
def test_chain_has_a_node_per_link_and_an_edge_per_joint(name, tmp_path, capsys):
    path = str(ROBOTS / f"{name}.urdf")
    assert main(["info", path, "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    png = tmp_path / "chain.png"
    assert main(["draw", path, "--chain", "--png", str(png), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert len(d["nodes"]) == info["links"] and len(d["edges"]) == len(info["joints"])
    assert d["loops"] == info["loops"]
    assert png.exists() and ink(png)[0] > 0.005
    mech, q = assembled(path)
    fig = draw_chain(kinematic_chain(mech, q))
    kinds, _ = gids(fig)
    assert kinds["node"] == info["links"] and kinds["edge"] == len(info["joints"])
    plt.close(fig)


def test_watt_chain_has_two_ternary_links():
    mech, q = assembled(str(ROBOTS / "watt_sixbar.urdf"))
    chain = kinematic_chain(mech, q)
    assert sorted(n.degree for n in chain.nodes) == [2, 2, 2, 2, 3, 3]
    assert chain.count == 1 and chain.count_name == "Gruebler"
    skel = skeleton(mech, q)
    assert sum(lk.shape == "polygon" for lk in skel.links) == 2  # ternary links as filled triangles


def _collinear_inputs_fourbar():
    """Crank angles (absolute, from the ground line) where crank and coupler are collinear:
    |AC| = b + a (extended) or b - a (folded), law of cosines in triangle A C D, C above AD
    (the file's circuit)."""
    g, a, b, c = 0.10, 0.04, 0.12, 0.08
    out = []
    for ac, folded in ((b + a, False), (b - a, True)):
        phi = np.arccos((ac**2 + g**2 - c**2) / (2 * ac * g))  # angle C A D
        out.append(phi + np.pi if folded else phi)
    return out


def _collinear_inputs_slider():
    """Crank angles where crank and rod are collinear: C on the slide y = e at |AC| = b +- a."""
    a, b, e = 0.05, 0.15, 0.02
    ext = np.arctan2(e, np.sqrt((a + b) ** 2 - e**2))
    fold = np.arctan2(e, np.sqrt((b - a) ** 2 - e**2)) + np.pi
    return [ext, fold]


def _wrap(x):
    return np.mod(np.asarray(x) + np.pi, 2 * np.pi) - np.pi


@pytest.mark.parametrize("path, expected", [(FOURBAR, _collinear_inputs_fourbar), (SLIDER, _collinear_inputs_slider)])
def test_singular_drawings_at_the_dead_centres(path, expected, tmp_path, capsys):
    png = tmp_path / "s.png"
    assert main(["draw", path, "--singular", "--png", str(png), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    found = d["singular_configurations"]
    mech, _ = assembled(path)
    search = singular_configurations(mech)
    assert len(found) == len(search.found) == 2
    assert all(s["kind"] == "serial" for s in found)
    files = sorted(tmp_path.glob("s-singular-*.png"))
    assert [f.name for f in files] == ["s-singular-1.png", "s-singular-2.png"]
    assert d["files"] == [str(f) for f in files]
    # the crank joint is at 0 with the crank drawn at 60 deg: absolute angle = joint value + 60 deg
    absolute = sorted(_wrap([s["input"] + np.radians(60) for s in found]))
    np.testing.assert_allclose(absolute, sorted(_wrap(expected())), atol=1e-8)
    for f in files:
        assert ink(f)[0] > 0.005


def test_singular_figure_title_says_the_kind(tmp_path, capsys):
    assert main(["draw", FOURBAR, "--singular", "--png", str(tmp_path / "s.png")]) == 0
    out = capsys.readouterr().out.strip().splitlines()
    assert len(out) == 2
    assert all(line.startswith("serial singularity of 'rocker'") and "crank_joint = " in line for line in out)


def test_non_grashof_limit_positions_are_found_too(tmp_path, capsys):
    path = str(ROBOTS / "fourbar_non_grashof.urdf")
    assert main(["draw", path, "--singular", "--svg", str(tmp_path / "n.svg"), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    kinds = Counter((s["kind"], s["limit"]) for s in d["singular_configurations"])
    assert kinds[("actuator", True)] == 2  # the input's own limit positions
    assert len(list(tmp_path.glob("n-singular-*.svg"))) == len(d["singular_configurations"])


@pytest.mark.parametrize("name", ["bennett", "delta_parallelogram", "spherical_fourbar"])
def test_spatial_mechanisms_get_a_projection(name, tmp_path, capsys):
    path = str(ROBOTS / f"{name}.urdf")
    png = tmp_path / "p.png"
    assert main(["draw", path, "--png", str(png), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["planar"] is False
    mech, q = assembled(path)
    skel = skeleton(mech, q)
    e1, e2, n = (np.array(v) for v in skel.basis)
    np.testing.assert_allclose([e1 @ e2, e1 @ n, e2 @ n], 0, atol=1e-12)
    fig = draw_mechanism(skel)
    kinds, _ = gids(fig)
    assert kinds["link"] == len(skel.links) == mech.topology(q).n_links
    assert kinds["joint"] == len(skel.joints) == mech.topology(q).n_joints
    plt.close(fig)
    assert ink(png)[0] > 0.005


def test_higher_pairs_are_drawn_as_their_profiles():
    mech, q = assembled(str(ROBOTS / "cam_followers.urdf"))
    skel = skeleton(mech, q)
    shapes = sorted((p.joint, p.shape) for p in skel.profiles)
    assert shapes == [("B", "circle"), ("B", "line"), ("D", "circle"), ("D", "point")]
    cam = next(p for p in skel.profiles if p.shape == "circle")
    assert cam.radius == pytest.approx(0.03)
    fig = draw_mechanism(skel)
    kinds, _ = gids(fig)
    assert kinds["profile"] == 4 and kinds["link"] == 4 and kinds["joint"] == 5
    plt.close(fig)
    mech, q = assembled(str(ROBOTS / "rack_pinion.urdf"))
    skel = skeleton(mech, q)
    assert sorted(p.shape for p in skel.profiles) == ["circle", "line"]


@pytest.mark.parametrize("args, message", [
    (["--png", "x.jpg"], "--png expects a file name ending in .png"),
    (["--svg", "x.png"], "--svg expects a file name ending in .svg"),
    ([], "give --png F.png or --svg F.svg"),
    (["--png", "x.png", "--chain", "--singular"], "separate drawings"),
])
def test_bad_output_is_a_usage_error(args, message, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["draw", FOURBAR, *args]) == 2
    err = capsys.readouterr().err
    # (a file name the picture option does not take is refused with the command line, before the file is read)
    assert err.count("\n") == 1 and message in err and (FOURBAR in err or "expects a file name" in message)
    assert not list(tmp_path.iterdir())


def test_the_users_joint_letters_are_kept_and_links_numbered_once(tmp_path):
    """The quick start's four-bar names its joints O2, A, O4 and B (the loop joint): the drawing keeps
    them; equations numbers the links as draw does (ground 1, crank 2, coupler 3, rocker 4)."""
    from screwkin.analysis.course.equations import equations

    text = (ROBOTS.parent / "README.md").read_text().split("cat > fourbar.urdf <<'EOF'\n", 1)[1].split("\nEOF\n")[0]
    path = tmp_path / "fourbar.urdf"
    path.write_text(text)
    mech, q = assembled(str(path))
    skel = skeleton(mech, q)
    assert {j.letter: j.name for j in skel.joints} == {"O2": "O2", "A": "A", "O4": "O4", "B": "B"}
    numbers = {lk.name: lk.number for lk in skel.links}
    assert numbers == {"ground": 1, "crank": 2, "coupler": 3, "rocker": 4}
    assert equations(mech, q).numbers == numbers
    # a mechanism whose joint names are long keeps the textbook letters A, B, C, D
    mech, q = assembled(FOURBAR)
    assert sorted(j.letter for j in skeleton(mech, q).joints) == ["A", "B", "C", "D"]


def test_trace_draws_a_coupler_curve_through_the_solved_point(tmp_path, capsys):
    """draw --point P=coupler:60mm,20mm --trace P: the path starts at the point solve reports and closes
    after a whole crank turn; the SVG carries it (gid trace:P)."""
    import json

    svg = tmp_path / "t.svg"
    argv = ["draw", FOURBAR, "--set", "crank_joint=30deg", "--point", "P=coupler:60mm,20mm", "--trace", "P",
            "--svg", str(svg), "--json", "--steps", "180"]
    assert main(argv) == 0
    d = json.loads(capsys.readouterr().out)
    path = np.array(d["traces"]["P"]["path"])
    assert d["traces"]["P"]["stopped_at"] is None and len(path) == 181
    assert main(["solve", FOURBAR, "--set", "crank_joint=30deg", "--point", "P=coupler:60mm,20mm", "--json"]) == 0
    p = json.loads(capsys.readouterr().out)["solutions"][0]["points"]["P"]["position"]
    np.testing.assert_allclose(path[0], p[:2], atol=1e-9)
    np.testing.assert_allclose(path[-1], path[0], atol=1e-9)  # a crank-rocker's coupler curve closes
    assert 'id="trace:P"' in svg.read_text()
    assert main(["draw", FOURBAR, "--svg", str(svg), "--trace", "Q"]) == 2
    assert "no --point Q=LINK:x,y,z" in capsys.readouterr().err


def test_singular_figures_at_one_input_say_which_mode(tmp_path, capsys, monkeypatch):
    """issue 25 item 16: two singular configurations at the same input value (two modes of another loop) got
    the same caption; each now says which of the modes at that input it is."""
    import dataclasses
    import json

    import screwkin.commands.draw as draw_command

    real = draw_command.singular_configurations

    def doubled(*args, **kwargs):
        search = real(*args, **kwargs)
        return dataclasses.replace(search, found=(search.found[0], search.found[0]) + tuple(search.found[1:]))

    monkeypatch.setattr(draw_command, "singular_configurations", doubled)
    assert main(["draw", FOURBAR, "--singular", "--png", str(tmp_path / "s.png"), "--json"]) == 0
    found = json.loads(capsys.readouterr().out)["singular_configurations"]
    assert "assembly mode 1 of the 2 at this input" in found[0]["title"]
    assert "assembly mode 2 of the 2 at this input" in found[1]["title"]
    assert "assembly mode" not in found[2]["title"]


@pytest.mark.parametrize("name", ["friction_wheels", "rack_pinion"])
def test_a_rolling_pair_is_drawn_where_its_pitch_curves_touch(name):
    """The pair's joint in the drawing is the contact point, by hand from the drawn profiles: two
    circles touching outside (radii 20 mm and 10 mm) meet r1 from circle 1's centre along the line of
    centres, 30 mm apart; a pinion on a rack line (gear radius1 inf) meets it at the foot of its
    centre on the line, 40 mm from it."""
    mech, q = assembled(ROBOTS / f"{name}.urdf")
    skel = skeleton(mech, q)
    joint = next(j for j in skel.joints if j.type in ("rolling", "gear"))
    first, second = (p for p in skel.profiles if p.joint == joint.letter)
    c1, c2, point = np.array(first.centre), np.array(second.centre), np.array(joint.point)
    if first.shape == "circle":
        assert np.linalg.norm(c2 - c1) == pytest.approx(first.radius + second.radius, abs=1e-9)
        np.testing.assert_allclose(point, c1 + first.radius * (c2 - c1) / np.linalg.norm(c2 - c1), rtol=0, atol=1e-12)
    else:
        u = np.array(first.direction)
        np.testing.assert_allclose(point, c1 + ((c2 - c1) @ u) * u, rtol=0, atol=1e-12)
        assert np.linalg.norm(c2 - point) == pytest.approx(second.radius, abs=1e-9)

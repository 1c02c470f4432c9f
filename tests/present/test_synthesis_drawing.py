"""Synthesis results shown as designs (issue 24 item 10): the targets written into the file
(<screwkin:targets>), read back and drawn by ``screwkin draw``; the coupler curve through the
path's points; function generation's targets in the angles typed.  Values are checked against
what the test itself computes: the poses and points as typed, coupler points by circle
intersection of the lengths written in the file, Freudenstein's mapping of x to phi and psi."""

import json
import math
import re

import numpy as np
import pinocchio as pin
import pytest
from conftest import check_urdf, circles

import screwkin
from screwkin.cli import main

POSES = [(0.0, 0.0, 0.0), (0.04, 0.02, math.radians(20)), (0.07, 0.06, math.radians(45))]
POSES_TEXT = "0,0,0; 0.04,0.02,20deg; 0.07,0.06,45deg"
PIVOTS_TEXT = "-0.03,-0.08; 0.10,-0.06"
POINTS = [(0.0, 0.0), (0.05, 0.02), (0.1, 0.05), (0.12, 0.1), (0.08, 0.12)]
POINTS_TEXT = "; ".join(f"{x},{y}" for x, y in POINTS)


def run_json(capsys, argv, code=0):
    got = main([*argv, "--json"])
    out = capsys.readouterr()
    assert got == code, out.err
    return json.loads(out.out), out.err


@pytest.fixture(scope="module")
def designs(tmp_path_factory):
    """The three kinds synthesized once: {kind: (file, JSON report)}."""
    import contextlib
    import io

    folder = tmp_path_factory.mktemp("designs")
    out = {}
    for kind, argv in (
        ("motion", ["--poses", POSES_TEXT, "--pivots", PIVOTS_TEXT]),
        ("path", ["--points", POINTS_TEXT]),
        ("function", ["--function", "log(x)", "--x-range", "1:2", "--input-range", "0:60deg",
                      "--output-range", "0:90deg"]),
    ):
        path = folder / f"{kind}.urdf"
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            assert main(["synthesize", kind, *argv, "-o", str(path), "--json"]) == 0
        out[kind] = (path, json.loads(buf.getvalue()))
    return out


# ------------------------------------------------------------------ the targets in the file


def test_the_file_carries_the_poses_as_typed_and_loads_without_a_warning(designs):
    path, _ = designs["motion"]
    warnings = []
    mech = screwkin.load(path, warn=warnings.append)
    assert warnings == [] and mech.spec.warnings == []
    got = mech.spec.targets
    assert [t.kind for t in got] == ["pose"] * 3
    assert {t.link for t in got} == {"coupler_frame"} and {t.input for t in got} == {"crank_joint"}
    for t, (x, y, th) in zip(got, POSES):
        np.testing.assert_allclose(t.xyz, (x, y, 0.0), rtol=0, atol=1e-15)
        assert t.yaw == pytest.approx(th, abs=1e-15)
    assert got[0].value == 0.0  # the file is drawn at the first position


def test_pinocchio_reads_the_file_as_if_the_element_were_not_there(designs):
    path, _ = designs["path"]
    text = path.read_text()
    assert "<screwkin:targets>" in text and 'xmlns:screwkin="urn:screwkin:urdf"' in text
    bare = re.sub(r"\s*<screwkin:targets>.*</screwkin:targets>", "", text, flags=re.S)
    bare = bare.replace(' xmlns:screwkin="urn:screwkin:urdf"', "")
    assert "screwkin:" not in bare
    a, b = pin.buildModelFromXML(text), pin.buildModelFromXML(bare)
    assert list(a.names) == list(b.names) and [f.name for f in a.frames] == [f.name for f in b.frames]
    q = pin.neutral(a)
    da, db = a.createData(), b.createData()
    pin.framesForwardKinematics(a, da, q)
    pin.framesForwardKinematics(b, db, q)
    for k in range(a.nframes):
        np.testing.assert_allclose(da.oMf[k].homogeneous, db.oMf[k].homogeneous, rtol=0, atol=0)


@pytest.mark.parametrize("edit, says", [
    ('kind="point"', "kind 'dot'"),
    ('link="coupler_point"', "link 'nowhere'"),
    ('input="crank_joint"', "input 'nojoint'"),
])
def test_a_broken_target_refuses_the_file_naming_the_problem(designs, tmp_path, capsys, edit, says):
    path, _ = designs["path"]
    bad_value = {"kind": "dot", "link": "nowhere", "input": "nojoint"}[edit.split("=")[0]]
    text = path.read_text().replace(edit, f'{edit.split("=")[0]}="{bad_value}"', 1)
    bad = tmp_path / "bad.urdf"
    bad.write_text(text)
    assert main(["mobility", str(bad)]) == 1
    err = capsys.readouterr().err
    assert "bad.urdf" in err and says in err and "Traceback" not in err


# ------------------------------------------------------------------ function generation as typed


def test_function_targets_are_reported_in_the_angles_typed(designs, capsys, tmp_path):
    _, report = designs["function"]
    x0, x1, p0, p1, s0, s1 = 1.0, 2.0, 0.0, 60.0, 0.0, 90.0
    xs = (x0 + x1) / 2 - (x1 - x0) / 2 * np.cos((2 * np.arange(1, 4) - 1) * np.pi / 6)  # Chebyshev, n = 3
    phi = p0 + (xs - x0) / (x1 - x0) * (p1 - p0)
    psi = s0 + (np.log(xs) - math.log(x0)) / (math.log(x1) - math.log(x0)) * (s1 - s0)
    typed = [p["as_typed"] for p in report["precision"]]
    np.testing.assert_allclose([t["x"] for t in typed], xs, rtol=0, atol=1e-12)
    np.testing.assert_allclose([t["phi_deg"] for t in typed], phi, rtol=0, atol=1e-9)
    np.testing.assert_allclose([t["psi_deg"] for t in typed], psi, rtol=0, atol=1e-9)
    np.testing.assert_allclose([t["psi_reached_deg"] for t in typed], psi, rtol=0, atol=1e-9)  # 3 points: exact
    assert all(0.0 <= t["psi_deg"] <= 90.0 for t in typed)  # inside --output-range, not -171 deg
    for key in ("target", "input_deg", "value", "error_deg"):  # the existing keys are kept
        assert key in report["precision"][0]
    # the text's table says the same numbers
    assert main(["synthesize", "function", "--function", "log(x)", "--x-range", "1:2", "--input-range", "0:60deg",
                 "--output-range", "0:90deg", "-o", str(tmp_path / "f.urdf")]) == 0
    text = capsys.readouterr().out
    for ph, ps in zip(phi, psi):
        assert f"phi {ph:.6g} deg -> psi {ps:.6g} deg" in text
    assert "psi -1" not in text


# ------------------------------------------------------------------ what `screwkin draw FILE` shows


def _figure_targets(path):
    """The Figure draw_mechanism makes of ``path`` with its targets: {gid: artist}."""
    from screwkin.analysis.course.skeleton import skeleton
    from screwkin.present.draw import draw_mechanism
    from screwkin.present.draw_targets import design_marks
    from screwkin.present.plots import pyplot

    mech = screwkin.load(path)
    q = mech.assemble().q
    skel = skeleton(mech, q)
    fig = draw_mechanism(skel, marks=design_marks(mech, q, skel)[1])
    found = {a.get_gid(): a for a in fig.findobj() if a.get_gid()}
    pyplot("test").close(fig)
    return found


def test_the_drawing_marks_each_pose_where_it_was_typed_with_the_frame_reached(designs):
    path, _ = designs["motion"]
    artists = _figure_targets(path)
    for k, (x, y, th) in enumerate(POSES, 1):
        np.testing.assert_allclose(np.ravel(artists[f"target:{k}"].get_data()), (x, y), rtol=0, atol=1e-15)
        np.testing.assert_allclose(np.ravel(artists[f"reached:{k}"].get_data()), (x, y), rtol=0, atol=1e-9)
        (p, tip) = artists[f"targetaxis:{k}"]._posA_posB
        assert math.atan2(tip[1] - p[1], tip[0] - p[0]) == pytest.approx(th, abs=1e-12)
        (p, tip) = artists[f"reachedaxis:{k}"]._posA_posB
        assert math.atan2(tip[1] - p[1], tip[0] - p[0]) == pytest.approx(th, abs=1e-9)
        assert artists[f"targetlabel:{k}"].get_text() == str(k)
    # the linkage ghosted at positions 2 and 3 (position 1 is the one drawn)
    assert {g.split(":")[1] for g in artists if g.startswith("ghost:")} == {"2", "3"}


def _written_fourbar(path):
    """The four-bar as its URDF writes it: pivots, lengths, the coupler point in the coupler's
    frame, the crank's and the rocker's angles at the drawn configuration."""
    import xml.etree.ElementTree as ET

    root = ET.parse(path).getroot()
    joints = {j.get("name"): j for j in root.findall("joint")}

    def origin(j):
        o = j.find("origin")
        return np.array([float(v) for v in o.get("xyz").split()[:2]]), float(o.get("rpy").split()[2])

    A0, crank0 = origin(joints["crank_joint"])
    B0, rocker0 = origin(joints["rocker_joint"])
    a = origin(joints["coupler_joint"])[0][0]
    loop = root.find("loop_joint")
    b = float(loop.find("link1").get("xyz").split()[0])
    c = float(loop.find("link2").get("xyz").split()[0])
    uv, _ = origin(joints["coupler_point_joint"])
    return A0, B0, a, b, c, uv, crank0, rocker0


def _coupler_point(fourbar, theta, sigma):
    """The coupler point at crank angle theta by circle intersection, on the side sigma of A -> B0."""
    A0, B0, a, b, c, uv, _, _ = fourbar
    A = A0 + a * np.array([math.cos(theta), math.sin(theta)])
    for B in circles(A, b, B0, c):
        d1, d2 = B0 - A, B - A
        if np.sign(d1[0] * d2[1] - d1[1] * d2[0]) == sigma:
            phi = math.atan2(*(B - A)[::-1])
            return A + np.array([[math.cos(phi), -math.sin(phi)], [math.sin(phi), math.cos(phi)]]) @ uv
    raise AssertionError("no intersection on that side")


def test_the_coupler_curve_passes_through_each_point_at_the_crank_angle_the_table_reports(designs, capsys, tmp_path):
    path, report = designs["path"]
    fourbar = _written_fourbar(path)
    A0, B0, a, b, c, uv, crank0, rocker0 = fourbar
    A = A0 + a * np.array([math.cos(crank0), math.sin(crank0)])
    B = B0 + c * np.array([math.cos(rocker0), math.sin(rocker0)])
    assert abs(np.hypot(*(B - A)) - b) < 1e-12  # the file is drawn closed
    sigma = np.sign((B0 - A)[0] * (B - A)[1] - (B0 - A)[1] * (B - A)[0])
    svg = tmp_path / "p.svg"
    drawn, _ = run_json(capsys, ["draw", str(path), "--svg", str(svg)])
    curve = np.array(drawn["traces"]["curve of coupler_point"]["path"])
    assert len(curve) > 300  # a whole turn of the crank (a crank-rocker), not only the points
    assert all(f'id="target:{k}"' in svg.read_text() for k in range(1, 6))
    for k, (entry, mark) in enumerate(zip(report["precision"], drawn["targets"])):
        theta = crank0 + math.radians(entry["input_deg"])  # the table's crank angle, from the drawn configuration
        P = _coupler_point(fourbar, theta, sigma)
        np.testing.assert_allclose(P, POINTS[k], rtol=0, atol=1e-9)  # the design does what was asked
        np.testing.assert_allclose(mark["target"], POINTS[k], rtol=0, atol=0)  # drawn where typed
        np.testing.assert_allclose(mark["reached"], P, rtol=0, atol=1e-9)
        i = mark["curve_index"]
        np.testing.assert_allclose(curve[i], P, rtol=0, atol=1e-9)  # the curve passes through it there
        turns = (mark["curve_input"] - math.radians(entry["input_deg"])) / (2 * math.pi)
        assert turns == pytest.approx(round(turns), abs=1e-12)
    # every vertex of the drawn curve is on the coupler curve (within the spacing of 3,600 samples of it)
    sample = np.array([_coupler_point(fourbar, t, sigma) for t in np.linspace(0, 2 * math.pi, 3601)])
    spacing = float(np.max(np.hypot(*np.diff(sample, axis=0).T)))
    gaps = [float(np.min(np.hypot(*(sample - p).T))) for p in curve]
    assert max(gaps) <= spacing


def test_function_targets_are_drawn_along_the_rocker_at_the_angles_typed(designs, capsys, tmp_path):
    path, report = designs["function"]
    drawn, _ = run_json(capsys, ["draw", str(path), "--png", str(tmp_path / "f.png")])
    assert [m["kind"] for m in drawn["targets"]] == ["angle"] * 3
    for mark, entry in zip(drawn["targets"], report["precision"]):
        psi = math.radians(entry["as_typed"]["psi_deg"])
        u = np.array(mark["direction"])
        assert abs(u[0] * math.sin(psi) - u[1] * math.cos(psi)) < 1e-12  # along the rocker's line at psi
        np.testing.assert_allclose(mark["reached_direction"], u, rtol=0, atol=1e-9)
        assert f"psi {entry['as_typed']['psi_deg']:.5g} deg" in mark["label"]


def test_no_targets_leaves_them_out_and_says_so_otherwise(designs, capsys, tmp_path):
    path, _ = designs["motion"]
    assert main(["draw", str(path), "--png", str(tmp_path / "a.png")]) == 0
    assert "drawn with the 3 target poses" in capsys.readouterr().out
    drawn, _ = run_json(capsys, ["draw", str(path), "--png", str(tmp_path / "b.png"), "--no-targets"])
    assert "targets" not in drawn


def test_synthesize_draw_writes_the_design_with_its_targets(tmp_path, capsys):
    out, svg = tmp_path / "p.urdf", tmp_path / "p.svg"
    report, _ = run_json(capsys, ["synthesize", "path", "--points", POINTS_TEXT, "-o", str(out), "--draw", str(svg)])
    assert report["drawing"]["file"] == str(svg) and svg.stat().st_size > 0
    for mark, xy in zip(report["drawing"]["targets"], POINTS):
        np.testing.assert_allclose(mark["target"], xy, rtol=0, atol=0)
        np.testing.assert_allclose(mark["reached"], xy, rtol=0, atol=1e-9)
    for key in ("kind", "file", "links", "pivots", "precision", "valid"):  # the existing keys are kept
        assert key in report
    assert main(["synthesize", "path", "--points", POINTS_TEXT, "-o", str(out), "--draw", str(tmp_path / "p.gif")]) == 2
    assert "--draw expects a file name ending in .png or .svg" in capsys.readouterr().err
    assert main(["synthesize", "chains", "--links", "4", "--dof", "1", "--draw", str(svg)]) == 2
    assert "not to 'synthesize chains'" in capsys.readouterr().err


def test_the_guided_frame_is_tied_to_the_coupler_pins_as_one_rigid_body(designs, capsys, tmp_path):
    path, report = designs["motion"]
    drawn, _ = run_json(capsys, ["draw", str(path), "--png", str(tmp_path / "m.png")])
    A, B = np.array(report["pivots"]["A"]), np.array(report["pivots"]["B"])
    u = np.array(POSES[0][:2])
    want = sorted([np.hypot(*(A - u)), np.hypot(*(B - u))])  # frame origin to the coupler's pins, as synthesized
    for mark in drawn["targets"]:
        assert len(mark["carrier"]) == 2
        got = sorted(np.hypot(*(np.array(c) - mark["reached"])) for c in mark["carrier"])
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)


@pytest.mark.slow
def test_the_report_of_a_synthesized_file_has_the_targets_figure(designs, capsys, tmp_path):
    path, _ = designs["path"]
    html = tmp_path / "p.html"
    assert main(["report", str(path), "--html", str(html)]) == 0
    capsys.readouterr()
    text = html.read_text()
    assert text.count('class="targets"') == 1 and "the 5 targets the file states" in text


def test_too_many_targets_or_a_pose_without_its_angle_refuse_the_file(designs, tmp_path, capsys):
    from screwkin.files.description import LIMITS

    path, _ = designs["motion"]
    text = path.read_text()
    one = re.search(r"    <screwkin:target [^\n]*/>\n", text).group(0)
    many = tmp_path / "many.urdf"
    many.write_text(text.replace(one, one * (LIMITS.targets + 1), 1))
    assert main(["mobility", str(many)]) == 1
    assert f"screwkin reads at most {LIMITS.targets}" in capsys.readouterr().err
    bare = tmp_path / "bare.urdf"
    bare.write_text(text.replace(one, re.sub(r' yaw="[^"]*"', "", one), 1))
    assert main(["mobility", str(bare)]) == 1
    assert "a pose target needs yaw" in capsys.readouterr().err


def test_a_curve_that_cannot_turn_fully_runs_between_both_limit_positions(designs, capsys, tmp_path):
    """The function generator is a triple rocker: a point target before the first position (crank
    turned back) is met on the curve too, traced back to the other limit position."""
    import xml.etree.ElementTree as ET

    path, _ = designs["function"]
    root = ET.parse(path).getroot()
    joints = {j.get("name"): j for j in root.findall("joint")}
    A0 = np.array([float(v) for v in joints["crank_joint"].find("origin").get("xyz").split()[:2]])
    crank0 = float(joints["crank_joint"].find("origin").get("rpy").split()[2])
    a = float(joints["coupler_joint"].find("origin").get("xyz").split()[0])
    text = path.read_text()
    extra = ""
    for v in (-0.1, 0.5):  # the coupler's frame origin is the crank pin A: A0 + a (cos, sin)(crank0 + v)
        A = A0 + a * np.array([math.cos(crank0 + v), math.sin(crank0 + v)])
        extra += (f'    <screwkin:target kind="point" link="coupler" input="crank_joint" value="{v!r}" '
                  f'xyz="{float(A[0])!r} {float(A[1])!r} 0" label="pin at {v}"/>\n')
    both = tmp_path / "both.urdf"
    both.write_text(text.replace("  </screwkin:targets>", extra + "  </screwkin:targets>", 1))
    drawn, _ = run_json(capsys, ["draw", str(both), "--png", str(tmp_path / "b.png")])
    trace = drawn["traces"]["curve of coupler"]
    assert len(trace["stopped_at"]) == 2  # a limit position each way
    curve = np.array(trace["path"])
    for mark in drawn["targets"][3:]:
        np.testing.assert_allclose(curve[mark["curve_index"]], mark["target"], rtol=0, atol=1e-9)
        assert mark["curve_input"] == pytest.approx(mark["value"], abs=1e-12)


def test_a_function_generators_limit_position_is_said_in_the_crank_angle_typed(tmp_path, capsys):
    """x**2 over phi 30..200 deg: the crank meets a limit position inside the range; the defect
    names it as typed too, where Freudenstein's four-bar (its K, ground 0.1 m) has A, B, B0 collinear."""
    report, _ = run_json(capsys, ["synthesize", "function", "--function", "x**2", "--x-range", "0:1",
                                  "--input-range", "30deg:200deg", "--output-range", "200deg:300deg",
                                  "-o", str(tmp_path / "f.urdf")])
    (defect,) = [d for d in report["defects"] if "cut short" in d]
    phi = math.radians(float(re.search(r"\(phi ([-0-9.e+]+) deg as typed\)", defect).group(1)))
    K1, K2, K3 = report["K"]
    d = 0.1
    a, c = d / K2, d / K1
    b = math.sqrt(a * a + c * c + d * d - 2 * a * c * K3)
    reach = math.hypot(d + a * math.cos(phi), a * math.sin(phi))  # |A - B0|, B0 at the origin
    # the message gives phi to 6 digits (within 5e-5 deg at 30 deg); |d reach / d phi| <= a d / reach
    tol = a * d / reach * math.radians(1e-4) + 1e-9
    assert min(abs(reach - (b + abs(c))), abs(reach - abs(b - abs(c)))) < tol
    assert 30 < math.degrees(phi) < 200


def test_many_targets_are_all_marked_and_twelve_numbered(tmp_path, capsys):
    from screwkin.present.draw_targets import NUMBERED

    out = tmp_path / "f.urdf"
    assert main(["synthesize", "function", "--function", "log(x)", "--x-range", "1:2", "--input-range", "0:60deg",
                 "--output-range", "0:90deg", "--points", "20", "-o", str(out)]) == 0
    capsys.readouterr()
    artists = _figure_targets(out)
    assert sum(g.startswith("target:") for g in artists) == 20  # every target marked
    labels = sorted(int(g.split(":")[1]) for g in artists if g.startswith("targetlabel:"))
    assert len(labels) == NUMBERED and labels[0] == 1 and labels[-1] == 20
    assert main(["draw", str(out), "--png", str(tmp_path / "f.png")]) == 0
    assert f"{NUMBERED} of them numbered, evenly chosen" in capsys.readouterr().out


def test_check_urdf_parses_the_file_with_its_targets(designs):
    for kind in ("motion", "path", "function"):
        path, _ = designs[kind]
        assert "Successfully Parsed XML" in check_urdf(path)

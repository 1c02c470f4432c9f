"""Linkage synthesis (issue 14): every answer against something computed here, outside the
synthesis code -- a four-bar chosen by hand and moved by circle intersection, Freudenstein's
equations solved with numpy.linalg, the published counts of kinematic chains -- and every
written file read back with screwkin's own load, solve and assembly."""

import json
import math

import numpy as np
import pytest
from conftest import circles

import screwkin
from screwkin.analysis.course.skeleton import numbering
from screwkin.analysis.design.synthesis.check import check_design
from screwkin.analysis.design.synthesis.designs import Dyad
from screwkin.analysis.design.synthesis.function import parse_function
from screwkin.analysis.design.synthesis.motion import motion_design
from screwkin.cli import main
from screwkin.errors import UsageError
from screwkin.files.writer import write_urdf

# ------------------------------------------------------------------ a crank-rocker chosen by hand
# ground pivots A0, B0; crank 35 mm, coupler 110 mm, rocker 75 mm; |A0B0| = 92.2 mm.
# s + l = 35 + 110 = 145 < p + q = 92.2 + 75 = 167.2 and the crank is shortest: a crank-rocker.
A0 = np.array([0.0, 0.0])
B0 = np.array([0.09, 0.02])
CRANK, COUPLER, ROCKER = 0.035, 0.11, 0.075
FRAME = np.array([0.04, 0.025])  # the guided frame's origin in the coupler (origin A, x along AB)
TURN = math.radians(15.0)  # and its x axis, turned from AB


def rot(t):
    return np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])


def angle(v):
    return math.atan2(v[1], v[0])


def place(theta, mode=0):
    """(pose (x, y, th) of the guided frame, A, B) at crank angle theta, assembly mode 0 or 1."""
    A = A0 + CRANK * np.array([math.cos(theta), math.sin(theta)])
    B = circles(A, COUPLER, B0, ROCKER)[mode]
    phi = angle(B - A)
    p = A + rot(phi) @ FRAME
    return (float(p[0]), float(p[1]), phi + TURN), A, B


def poses_text(poses):
    return "; ".join(",".join(repr(float(v)) for v in p) for p in poses)


def run(capsys, argv, code=0):
    got = main(argv)
    out = capsys.readouterr()
    assert got == code, out.err
    return out


def run_json(capsys, argv):
    return json.loads(run(capsys, argv + ["--json"]).out)


CONTRACT = {"kind", "file", "links", "pivots", "precision", "grashof", "transmission_angle_range", "defects", "valid"}


def solved_poses(capsys, path, crank_value):
    d = run_json(capsys, ["solve", str(path), "--set", f"crank_joint={crank_value!r}", "--output", "coupler_frame"])
    return [(s["output_position"][0], s["output_position"][1], s["output_rpy"][2], s["residual"])
            for s in d["solutions"]]


def wrap(x):
    return (x + math.pi) % (2 * math.pi) - math.pi


# ------------------------------------------------------------------ motion generation
def test_three_positions_recover_the_moving_pivots_and_solve_reaches_each_pose(tmp_path, capsys):
    thetas = np.radians([40.0, 95.0, 160.0])
    placed = [place(t) for t in thetas]
    poses = [p for p, _, _ in placed]
    out = tmp_path / "motion3.urdf"
    d = run_json(capsys, ["synthesize", "motion", "--poses", poses_text(poses), "--pivots",
                          f"{A0[0]},{A0[1]}; {B0[0]},{B0[1]}", "-o", str(out)])
    assert CONTRACT <= set(d) and d["kind"] == "motion" and d["file"] == str(out)
    assert d["valid"] and d["defects"] == []
    # the moving pivots in the coupler frame: A and B of the first pose, seen from that frame
    p1, A1, B1 = placed[0]
    R1 = rot(p1[2])
    for cand, world in zip(d["candidates"], (A1, B1)):
        np.testing.assert_allclose(cand["moving_local"], R1.T @ (world - np.array(p1[:2])), rtol=0, atol=1e-12)
        np.testing.assert_allclose(cand["moving"], world, rtol=0, atol=1e-12)
    np.testing.assert_allclose(d["pivots"]["A"], A1, atol=1e-12)
    np.testing.assert_allclose(d["pivots"]["B"], B1, atol=1e-12)
    for name, length in (("crank", CRANK), ("coupler", COUPLER), ("rocker", ROCKER)):
        assert d["links"][name]["length"] == pytest.approx(length, abs=1e-12)
    assert d["grashof"].startswith("Grashof crank-rocker")
    lo, hi = d["transmission_angle_range"]
    # the transmission angle at the three poses themselves, from the closed form, lies in the range
    for _, A, B in placed:
        mu = math.degrees(math.acos(np.dot(A - B, B0 - B) / (COUPLER * ROCKER)))
        assert lo - 1e-6 <= mu <= hi + 1e-6
    # the file is drawn closed at the first pose, and every command loads it
    mech = screwkin.load(out)
    assert mech.assemble().iterations == 0
    assert mech.mobility().mobility == 1
    # screwkin solve reaches each pose (one of its assembly modes) to 1e-9
    for (pose, _, _), t in zip(placed, thetas, strict=True):
        got = solved_poses(capsys, out, float(t - thetas[0]))
        best = min(got, key=lambda s: math.hypot(s[0] - pose[0], s[1] - pose[1]))
        assert math.hypot(best[0] - pose[0], best[1] - pose[1]) < 1e-9
        assert abs(wrap(best[2] - pose[2])) < 1e-9 and best[3] < 1e-9
    for p in d["precision"]:
        assert p["reached"] and p["error"] < 1e-9 and p["angle_error_deg"] < 1e-7 and p["residual"] < 1e-9


def test_three_positions_with_the_moving_pivots_given_find_the_fixed_pivots(tmp_path, capsys):
    thetas = np.radians([40.0, 95.0, 160.0])
    placed = [place(t) for t in thetas]
    p1, A1, B1 = placed[0]
    local = [rot(p1[2]).T @ (w - np.array(p1[:2])) for w in (A1, B1)]
    d = run_json(capsys, ["synthesize", "motion", "--poses", poses_text([p for p, _, _ in placed]), "--moving",
                          "; ".join(f"{float(v[0])!r},{float(v[1])!r}" for v in local), "-o", str(tmp_path / "m.urdf")])
    np.testing.assert_allclose(d["pivots"]["A0"], A0, atol=1e-12)
    np.testing.assert_allclose(d["pivots"]["B0"], B0, atol=1e-12)
    assert d["valid"]


def test_poses_on_two_circuits_are_a_branch_defect_and_rejected(tmp_path, capsys):
    """Poses 1 and 2 on one assembly mode of the crank-rocker, pose 3 on the other: the same
    linkage is synthesized (three poses and the fixed pivots fix it), and it cannot move from
    pose 1 to pose 3 without being taken apart."""
    placed = [place(math.radians(t), m) for t, m in ((40.0, 0), (95.0, 0), (200.0, 1))]
    poses = poses_text([p for p, _, _ in placed])
    pivots = f"{A0[0]},{A0[1]}; {B0[0]},{B0[1]}"
    out = tmp_path / "branch.urdf"
    d = run_json(capsys, ["synthesize", "motion", "--poses", poses, "--pivots", pivots, "-o", str(out)])
    assert d["links"]["coupler"]["length"] == pytest.approx(COUPLER, abs=1e-12)
    assert not d["valid"]
    assert len(d["defects"]) == 1 and d["defects"][0].startswith("branch (circuit) defect") \
        and "position 3" in d["defects"][0]
    assert all(p["reached"] for p in d["precision"])  # each pose alone is reached (solve finds both modes)
    text = run(capsys, ["synthesize", "motion", "--poses", poses, "--pivots", pivots, "-o", str(out)]).out
    assert "DEFECTS:" in text and "not valid" in text
    rejected = tmp_path / "rejected.urdf"
    err = run(capsys, ["synthesize", "motion", "--poses", poses, "--pivots", pivots, "-o", str(rejected),
                       "--reject-defects"], code=1).err
    assert err.count("\n") == 1 and "branch (circuit) defect" in err and "--reject-defects" in err
    assert not rejected.exists() and not list(tmp_path.glob(".screwkin-*"))


def _dyads(placed):
    p1, A1, B1 = placed[0]
    R1 = rot(p1[2])
    return [Dyad(tuple(fixed), tuple(w), tuple(R1.T @ (w - np.array(p1[:2])))) for fixed, w in ((A0, A1), (B0, B1))]


def test_positions_out_of_order_are_an_order_defect(tmp_path):
    """Four poses of the crank-rocker at crank angles 40, 170, 95, 250 deg: each is reached on one
    circuit, but turning the crank either way meets them as 1, 3, 2, 4 or 1, 4, 2, 3."""
    placed = [place(math.radians(t)) for t in (40.0, 170.0, 95.0, 250.0)]
    design = motion_design([p for p, _, _ in placed], *_dyads(placed))
    path = tmp_path / "order.urdf"
    path.write_text(write_urdf(design.linkage))
    check = check_design(design, path)
    assert all(p.reached for p in check.precision)
    assert [d for d in check.defects if d.startswith("order defect")] == list(check.defects) and check.defects
    assert "1, 3, 2, 4" in check.defects[0] or "1, 4, 2, 3" in check.defects[0]
    assert not check.valid


def test_a_pose_beyond_a_limit_position_is_reported(tmp_path):
    """The non-Grashof 5-7-9-6 in four-bar of tests/data/student rocks: its crank stops where
    |A B0| = rocker - coupler, cos(theta) = (a^2 + d^2 - (c - b)^2) / (2 a d) = 0.95, and turns
    back on the other branch.  A pose on that other branch is beyond the limit position."""
    global A0, B0, CRANK, COUPLER, ROCKER
    saved = (A0, B0, CRANK, COUPLER, ROCKER)
    IN = 0.0254
    A0, B0, CRANK, COUPLER, ROCKER = np.zeros(2), np.array([6 * IN, 0.0]), 5 * IN, 7 * IN, 9 * IN
    try:
        placed = [place(math.radians(t), m) for t, m in ((45.0, 0), (120.0, 0), (60.0, 1))]
        design = motion_design([p for p, _, _ in placed], *_dyads(placed))
    finally:
        A0, B0, CRANK, COUPLER, ROCKER = saved
    path = tmp_path / "limit.urdf"
    path.write_text(write_urdf(design.linkage))
    check = check_design(design, path)
    assert check.grashof.startswith("non-Grashof")
    limit = math.degrees(math.acos(0.95))  # 18.19 deg: the crank stops there, turning clockwise from 45 deg
    stops = [d for d in check.defects if "beyond a limit position" in d]
    assert len(stops) == 1 and "position 3" in stops[0]
    assert f"stops {45 - limit:.6g} deg clockwise from position 1" in stops[0]
    assert any(d.startswith("branch") for d in check.defects)  # counterclockwise the crank passes 60 deg on branch 1
    assert check.travel[1] == pytest.approx(math.radians(75.0), abs=1e-9) and check.travel[2] is None


def test_four_positions_burmester_pick_and_five_positions_find_the_linkage(tmp_path, capsys):
    thetas = [40.0, 95.0, 160.0, 230.0, 300.0]
    placed = [place(math.radians(t)) for t in thetas]
    poses = [p for p, _, _ in placed]
    png = tmp_path / "burmester.png"
    d4 = run_json(capsys, ["synthesize", "motion", "--poses", poses_text(poses[:4]), "-o", str(tmp_path / "m4.urdf"),
                           "--png", str(png)])
    assert png.stat().st_size > 10_000 and len(d4["candidates"]) >= 8
    assert d4["valid"] and all(p["reached"] and p["error"] < 1e-9 for p in d4["precision"])
    # every candidate's moving pivot: its four positions on one circle about its fixed pivot (computed here)
    for c in d4["candidates"]:
        r = [np.linalg.norm(rot(p[2]) @ np.array(c["moving_local"]) + np.array(p[:2]) - np.array(c["fixed"]))
             for p in poses[:4]]
        assert max(r) - min(r) < 1e-9
    # five positions: the Burmester points include the linkage's own fixed pivots
    d5 = run_json(capsys, ["synthesize", "motion", "--poses", poses_text(poses), "-o", str(tmp_path / "m5.urdf")])
    fixed = np.array([c["fixed"] for c in d5["candidates"]])
    assert 2 <= len(fixed) <= 4
    for pivot in (A0, B0):
        assert np.min(np.linalg.norm(fixed - pivot, axis=1)) < 1e-9
    k = [int(np.argmin(np.linalg.norm(fixed - pivot, axis=1))) for pivot in (A0, B0)]
    d = run_json(capsys, ["synthesize", "motion", "--poses", poses_text(poses), "--pick", f"{k[0]},{k[1]}",
                          "-o", str(tmp_path / "pick.urdf")])
    assert d["pick"] == k and d["valid"]
    assert d["links"]["coupler"]["length"] == pytest.approx(COUPLER, abs=1e-9)
    assert all(p["error"] < 1e-9 and p["angle_error_deg"] < 1e-7 for p in d["precision"])


# ------------------------------------------------------------------ function generation
def test_freudenstein_coefficients_and_structural_error(tmp_path, capsys):
    out = tmp_path / "log.urdf"
    d = run_json(capsys, ["synthesize", "function", "--function", "log(x)", "--x-range", "1:2", "--input-range",
                          "30deg:120deg", "--output-range", "240deg:330deg", "-o", str(out)])
    assert CONTRACT <= set(d) and d["kind"] == "function"
    # Chebyshev points and the angles, then Freudenstein's three equations solved here
    x = 1.5 - 0.5 * np.cos((2 * np.arange(1, 4) - 1) * np.pi / 6)
    phi = np.radians(30 + 90 * (x - 1))
    psi = np.radians(240 + 90 * np.log(x) / np.log(2))
    M = np.stack([np.cos(phi), -np.cos(psi), np.ones(3)], axis=1)
    K = np.linalg.solve(M, np.cos(phi - psi))
    np.testing.assert_allclose(d["precision_x"], x, rtol=0, atol=1e-15)
    np.testing.assert_allclose(d["K"], K, rtol=1e-12, atol=1e-14)
    # K1 = d / c, K2 = d / a, K3 = (a^2 - b^2 + c^2 + d^2) / (2 a c), ground d = 0.1 m
    a, c = 0.1 / K[1], 0.1 / K[0]
    b = math.sqrt(a * a + c * c + 0.01 - 2 * a * c * K[2])
    assert d["links"]["crank"]["length"] == pytest.approx(abs(a), rel=1e-12)
    assert d["links"]["rocker"]["length"] == pytest.approx(abs(c), rel=1e-12)
    assert d["links"]["coupler"]["length"] == pytest.approx(b, rel=1e-12)
    # structural error: zero at the precision points, not between them (both also computed here)
    assert max(abs(e) for e in d["structural_error_deg"]["at_precision_points"]) < 1e-9
    assert d["structural_error_deg"]["max"] > 1e-3
    A0f, B0f = np.array([0.1, 0.0]), np.zeros(2)

    def generated(ph):
        A = A0f + a * np.array([math.cos(ph), math.sin(ph)])
        return [angle(B - B0f) + (math.pi if c < 0 else 0.0) for B in circles(A, b, B0f, abs(c))]

    for ph, ps in zip(phi, psi, strict=True):
        assert min(abs(wrap(g - ps)) for g in generated(ph)) < 1e-12
    mids = (x[:-1] + x[1:]) / 2
    errs = [min(abs(wrap(g - np.radians(240 + 90 * math.log(m) / math.log(2)))) for g in generated(
        np.radians(30 + 90 * (m - 1)))) for m in mids]
    assert min(errs) > 1e-6 and max(errs) <= math.radians(d["structural_error_deg"]["max"]) + 1e-12
    # the written file, solved by screwkin, gives the rocker angle at each precision point to 1e-9
    assert d["valid"] and all(p["reached"] and p["error_deg"] < 1e-7 for p in d["precision"])
    for ph, ps in zip(phi, psi, strict=True):
        sol = run_json(capsys, ["solve", str(out), "--set", f"crank_joint={float(ph - phi[0])!r}"])["solutions"]
        rockers = [s["link_angles"]["rocker"] + (math.pi if c < 0 else 0.0) for s in sol]
        assert min(abs(wrap(r - ps)) for r in rockers) < 1e-9


def test_least_squares_function_generation_uses_more_points(tmp_path, capsys):
    d = run_json(capsys, ["synthesize", "function", "--function", "x**2", "--x-range", "0:1", "--input-range",
                          "60deg:150deg", "--output-range", "30deg:120deg", "--points", "6", "--spacing", "even",
                          "-o", str(tmp_path / "sq.urdf")])
    x = np.linspace(0, 1, 6)
    phi, psi = np.radians(60 + 90 * x), np.radians(30 + 90 * x**2)
    M = np.stack([np.cos(phi), -np.cos(psi), np.ones(6)], axis=1)
    K, *_ = np.linalg.lstsq(M, np.cos(phi - psi), rcond=None)
    np.testing.assert_allclose(d["K"], K, rtol=1e-10, atol=1e-12)
    assert d["least_squares"] and len(d["precision"]) == 6


def test_the_function_evaluator_is_restricted():
    f = parse_function("log(x) + 2*x**2 - sqrt(abs(x)) / e + sin(pi*x) - -1")
    x = np.array([0.5, 1.0, 2.0])
    np.testing.assert_allclose(f(x), np.log(x) + 2 * x**2 - np.sqrt(x) / np.e + np.sin(np.pi * x) + 1)
    for text in ("x.__class__", "__import__('os')", "open('f')", "(lambda: 1)()", "[1, 2]", "x if x else 1",
                 "y + 1", "log(x, 2)", "'a'", "x +", "1" + "+1" * 300, "exp(x)(1)"):
        with pytest.raises(UsageError):
            parse_function(text)


# ------------------------------------------------------------------ path generation
def test_path_through_points_of_a_known_coupler_curve(tmp_path, capsys):
    """Five points of a coupler point of the crank-rocker, at crank angles 20, 70, 120, 180, 250
    deg (the timing given): the linkage found passes through them, and what screwkin's solve does
    with the written file agrees with the circle intersection computed here."""
    thetas = np.radians([20.0, 70.0, 120.0, 180.0, 250.0])
    points = [place(t)[0][:2] for t in thetas]
    out = tmp_path / "path.urdf"
    d = run_json(capsys, ["synthesize", "path", "--points", "; ".join(f"{x!r},{y!r}" for x, y in points),
                          "--timing", ", ".join(f"{math.degrees(t - thetas[0])!r}deg" for t in thetas),
                          "--starts", "8", "-o", str(out)])
    assert CONTRACT <= set(d) and d["kind"] == "path" and d["valid"]
    assert max(d["errors"]) < 1e-9
    A0p, B0p = np.array(d["pivots"]["A0"]), np.array(d["pivots"]["B0"])
    a, b, c = (d["links"][k]["length"] for k in ("crank", "coupler", "rocker"))
    u, v = d["links"]["coupler"]["point"]["x"], d["links"]["coupler"]["point"]["y"]
    t1 = angle(np.array(d["pivots"]["A"]) - A0p)
    for (px, py), t in zip(points, thetas, strict=True):
        value = t - thetas[0]
        sol = run_json(capsys, ["solve", str(out), "--set", f"crank_joint={float(value)!r}", "--output", "coupler_point",
                                  "--starts", "2"])
        got = [np.array(s["output_position"][:2]) for s in sol["solutions"]]
        A = A0p + a * np.array([math.cos(t1 + value), math.sin(t1 + value)])
        closed = [A + rot(angle(B - A)) @ np.array([u, v]) for B in circles(A, b, B0p, c)]
        best = min(got, key=lambda g: math.hypot(g[0] - px, g[1] - py))
        assert math.hypot(best[0] - px, best[1] - py) < 1e-9
        assert min(np.linalg.norm(best - q) for q in closed) < 1e-9
    assert all(p["closed_form_error"] < 1e-9 for p in d["precision"])


# ------------------------------------------------------------------ type and number synthesis
def test_chain_counts_match_the_published_numbers(capsys):
    """Planar 1-DOF chains with revolute joints: 1 with 4 links, 2 with 6 (Watt, Stephenson), 16
    with 8; their mechanisms (inversions) 1, 2 + 3, and 71 with 8 links (Tsai, Mechanism Design:
    Enumeration of Kinematic Structures According to Function, 2001, ch. 4)."""
    d4 = run_json(capsys, ["synthesize", "chains", "--links", "4", "--dof", "1", "--planar"])
    assert CONTRACT <= set(d4) and (d4["count"], d4["mechanisms"], d4["joints"]) == (1, 1, 4)
    d6 = run_json(capsys, ["synthesize", "chains", "--links", "6", "--dof", "1"])
    assert d6["count"] == 2
    for chain in d6["chains"]:
        ternary = [k for k, n in enumerate(chain["joints_per_link"]) if n == 3]
        assert sorted(chain["joints_per_link"]) == [2, 2, 2, 2, 3, 3] and len(ternary) == 2
        adjacent = any(sorted(j["links"]) == ternary for j in chain["joints"])
        assert chain["name"].startswith("Watt" if adjacent else "Stephenson")
        assert len(chain["mechanisms"]) == (2 if adjacent else 3)
    assert {c["name"].split()[0] for c in d6["chains"]} == {"Watt", "Stephenson"}
    d8 = run_json(capsys, ["synthesize", "chains", "--links", "8", "--dof", "1"])
    assert (d8["count"], d8["mechanisms"]) == (16, 71)


def test_slider_crank_family_and_written_chains(tmp_path, capsys):
    d = run_json(capsys, ["synthesize", "chains", "--links", "4", "--dof", "1", "--prismatic", "1",
                          "-o", str(tmp_path / "sc")])
    assert d["count"] == 1 and d["chains"][0]["name"].startswith("slider-crank")
    joints = d["chains"][0]["joints"]
    assert sorted(j["type"] for j in joints) == ["P", "R", "R", "R"]
    # a slide's guide and block are different elements: the four textbook inversions
    assert d["mechanisms"] == 4 and d["valid"] and len(d["files"]) == 4
    two = run_json(capsys, ["synthesize", "chains", "--links", "4", "--dof", "1", "--prismatic", "2"])
    assert two["count"] == 2  # RRPP (sliders adjacent) and RPRP
    # every written mechanism loads, is drawn closed and has mobility 1 by screwkin's constraint rank
    d6 = run_json(capsys, ["synthesize", "chains", "--links", "6", "--dof", "1", "-o", str(tmp_path / "six")])
    assert len(d6["files"]) == 5
    for f in d6["files"] + d["files"]:
        mech = screwkin.load(f)
        r = mech.mobility()
        assert mech.assemble().iterations == 0 and r.mobility == 1
        assert r.topology.loops == len(mech.cuts)  # one loop joint per independent loop
        # the file's link names are the numbers screwkin draw gives the links (the ground link1)
        number, _, _ = numbering(r.topology, list(mech.actuated))
        assert all(name == f"link{k}" for name, k in number.items()), number


def test_slide_inversions_are_the_textbooks(capsys):
    """Slider-crank chain: frame (the guide), crank (next to the frame), coupler (next to the block)
    and block grounded -- four mechanisms; double slider with adjacent slides: the guide of both
    (elliptical trammel), a block (Scotch yoke), the link joining the blocks (Oldham coupling)."""
    d = run_json(capsys, ["synthesize", "chains", "--links", "4", "--dof", "1", "--prismatic", "1"])
    chain = d["chains"][0]
    (u, v), guide = next((tuple(j["links"]), j["guide"]) for j in chain["joints"] if j["type"] == "P")
    block = v if guide == u else u
    neighbours = {x: {y for j in chain["joints"] for y in j["links"] if x in j["links"] and y != x} for x in range(4)}
    crank = next(x for x in neighbours[guide] if x != block)
    coupler = next(x for x in neighbours[block] if x != guide)
    assert sorted(m["ground"] for m in chain["mechanisms"]) == sorted([guide, crank, coupler, block])
    d = run_json(capsys, ["synthesize", "chains", "--links", "4", "--dof", "1", "--prismatic", "2"])
    rrpp = next(c for c in d["chains"] if "adjacent" in c["name"])
    slides = [j for j in rrpp["joints"] if j["type"] == "P"]
    common = slides[0]["guide"]
    assert all(j["guide"] == common for j in slides)  # the link carrying both slides guides them
    blocks = {x for j in slides for x in j["links"] if x != common}
    rod = ({0, 1, 2, 3} - blocks - {common}).pop()
    grounds = [m["ground"] for m in rrpp["mechanisms"]]
    assert len(grounds) == 3 and common in grounds and rod in grounds and len(blocks & set(grounds)) == 1


# ------------------------------------------------------------------ the command line
def test_errors_are_one_line(tmp_path, capsys):
    out = str(tmp_path / "x.urdf")
    good = poses_text([place(math.radians(t))[0] for t in (40.0, 95.0, 160.0)])
    cases = [
        (["--poses", "0,0,0; 1,2; 3,4,5", "--pivots", "0,0; 1,0"], 2, "has 2 numbers, expected 3"),
        (["--poses", "0,0,10deg; 1,0,0; 0,0,10deg", "--pivots", "0,0; 1,0"], 2, "positions 1 and 3 are the same"),
        (["--poses", "0,0,1zz; 1,0,0; 2,0,0", "--pivots", "0,0; 1,0"], 2, "unknown unit"),
        (["--poses", good], 2, "need either the two fixed pivots"),
        (["--poses", good, "--pivots", "0,0; 1,0", "--links", "4"], 2, "applies to 'synthesize chains'"),
        # a pure translation moves every point on a line: no circle, no dyad
        (["--poses", "0,0,0; 0.1,0,0; 0.2,0,0", "--moving", "0,0; 0,0.1"], 1, "moves on a straight line"),
    ]
    for args, code, words in cases:
        err = run(capsys, ["synthesize", "motion", *args, "-o", out], code=code).err
        assert err.startswith("screwkin: error: ") and err.count("\n") == 1 and words in err, err
    # a fixed pivot at the pole of two positions has no moving pivot: unreachable, exit 1.  Turning by
    # 90 deg about P takes the origin to (0.1, 0): (I - R) P = (0.1, 0), P = (0.05, 0.05)
    poses = [(0.0, 0.0, 0.0), (0.1, 0.0, math.pi / 2), (0.0, 0.2, math.pi / 3)]
    err = run(capsys, ["synthesize", "motion", "--poses", poses_text(poses), "--pivots", "0.05,0.05; 0.3,0.2",
                       "-o", out], code=1).err
    assert err.count("\n") == 1 and "is a pole" in err
    err = run(capsys, ["synthesize", "function", "--function", "x.real", "--x-range", "1:2", "--input-range", "0:1",
                       "--output-range", "0:1", "-o", out], code=2).err
    assert err.count("\n") == 1 and "not allowed" in err
    err = run(capsys, ["synthesize", "chains", "--links", "5", "--dof", "1"], code=2).err
    assert err.count("\n") == 1 and "Gruebler" in err
    assert not (tmp_path / "x.urdf").exists()

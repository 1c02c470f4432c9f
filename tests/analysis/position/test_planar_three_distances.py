"""Every assembly mode of a planar platform on three distances (a 3-RPR) in closed form
(analysis.position.three_distances, model.planar_distances), against what is written here with plain
numpy: the forward-kinematics polynomial in t = tan(phi / 2) (the two leg equations less the first are
linear in the platform point B1; B1 = adj(M) rhs / det M put into the first, denominators cleared), whose
genuine roots (det M != 0, t != +-i) are the poses; each pose's leg lengths computed from its joint values;
and the homotopy route (certified.certified_modes: monodromy and the trace test) finding the same modes."""

import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from conftest import ROBOTS
from loci_robots import RPR_BASE, RPR_HOME, RPR_PLATFORM, rpr3, rpr3_polynomial
from numpy.polynomial import Polynomial

import screwkin
from screwkin.analysis.position import certified
from screwkin.analysis.position.position import PositionSolver
from screwkin.cli import main
from screwkin.errors import AssemblyError
from screwkin.model.planar_distances import planar_poses

BUNDLED = ROBOTS / "planar_3rpr.urdf"
METHOD = "closed form (a univariate polynomial of degree 6 in tan(phi/2))"


def rot(phi):
    c, s = np.cos(phi), np.sin(phi)
    return np.array([[c, -s], [s, c]])


def genuine_roots(A, b, rho):
    """The roots t of the 3-RPR's polynomial that are poses: ground points A (3, 2), platform points b (3, 2)
    in the platform's frame (phi = 0: as drawn), leg lengths rho.  |B1 + R (b_k - b_1) - A_k|^2 = rho_k^2:
    rows k = 2, 3 less row 1 are M(t) B1 = rhs(t), everything times (1 + t^2); B1 = adj(M) rhs / det M in
    row 1.  Returns (the roots, det as a polynomial)."""
    one, c, s = Polynomial([1, 0, 1]), Polynomial([1, 0, -1]), Polynomial([0, 2])
    d = b - b[0]
    M, rhs = [], []
    for k in (1, 2):
        Rd = (d[k][0] * c - d[k][1] * s, d[k][0] * s + d[k][1] * c)  # (1 + t^2) R d_k
        w = (Rd[0] - A[k][0] * one, Rd[1] - A[k][1] * one)  # (1 + t^2) (R d_k - A_k)
        M.append((2 * (w[0] + A[0][0] * one), 2 * (w[1] + A[0][1] * one)))
        # |R d_k - A_k|^2 = |d_k|^2 + |A_k|^2 - 2 A_k . R d_k, times (1 + t^2)
        w2 = (d[k] @ d[k] + A[k] @ A[k]) * one - 2 * (A[k][0] * Rd[0] + A[k][1] * Rd[1])
        rhs.append((rho[k] ** 2 - rho[0] ** 2 + A[0] @ A[0]) * one - w2)
    det = M[0][0] * M[1][1] - M[0][1] * M[1][0]
    N = (M[1][1] * rhs[0] - M[0][1] * rhs[1], M[0][0] * rhs[1] - M[1][0] * rhs[0])
    P = N[0] ** 2 + N[1] ** 2 - 2 * (A[0][0] * N[0] + A[0][1] * N[1]) * det + (A[0] @ A[0] - rho[0] ** 2) * det ** 2
    out = []
    for t in P.roots():
        if abs(abs(t) - 1) < 1e-6 and abs(t.real) < 1e-6:
            continue  # t = +-i
        if abs(det(t)) < 1e-9 * np.abs(det.coef).max():
            continue  # det M = 0: the linear rows give no B1
        out.append(t)
    return np.array(out), det


def legs_of(path):
    """From the URDF's text: each leg's ground point A, its end at slide 0 (in the cylinder's frame) w and
    slide axis u, and the platform points b (in wrist1's frame) -- the bundled file's layout."""
    root = ET.parse(path).getroot()
    j = {e.get("name"): e for e in root if e.tag in ("joint", "loop_joint")}
    xy = lambda s: np.array([float(v) for v in s.split()[:2]])  # noqa: E731
    A = np.array([xy(j[f"base{k}"].find("origin").get("xyz")) for k in (1, 2, 3)])
    u = np.array([xy(j[f"leg{k}"].find("axis").get("xyz")) for k in (1, 2, 3)])
    w = [xy(j["wrist1"].find("origin").get("xyz"))] + [xy(j[f"wrist{k}"].find("link1").get("xyz")) for k in (2, 3)]
    b = [np.zeros(2)] + [xy(j[f"wrist{k}"].find("link2").get("xyz")) for k in (2, 3)]
    return A, np.array(w), u, np.array(b)


def check_pose(sol, A, w, u, b, rho0):
    """The platform placed from leg 1's joints alone (base1, leg1, wrist1); every leg's length from that pose
    is the input's, and each leg's own joints reach its platform point.  Returns the platform's turn phi."""
    J = sol.joints
    x = np.array([J[f"leg{k}"] for k in (1, 2, 3)])
    B1 = A[0] + rot(J["base1"]) @ (w[0] + x[0] * u[0])
    phi = J["base1"] + J["wrist1"]
    for k in range(3):
        B = B1 + rot(phi) @ b[k]
        assert abs(np.linalg.norm(B - A[k]) - (rho0[k] + x[k])) < 1e-9
        end = A[k] + rot(J[f"base{k + 1}"]) @ (w[k] + x[k] * u[k])
        assert np.abs(end - B).max() < 1e-9
    return phi


def test_the_bundled_3rpr_has_two_real_and_two_complex_modes_in_closed_form():
    A, w, u, b = legs_of(BUNDLED)
    rho0 = np.linalg.norm(w, axis=1)  # the legs' lengths at slide 0
    solver = PositionSolver(screwkin.load(BUNDLED))
    res = solver.solve({"leg1": 0.0, "leg2": 0.0, "leg3": 0.0})
    c = res.modes
    assert res.method == METHOD and c.method == METHOD and c.complete
    assert (c.real, c.complex, c.found) == (2, 2, 4)
    roots, det = genuine_roots(A, b - b[0], rho0)
    real = np.sort(roots[np.abs(roots.imag) < 1e-9].real)
    assert len(real) == 2 and len(roots) - len(real) == 2  # -0.3639702 and 0; -0.1290792 +- 0.523502 i
    np.testing.assert_allclose(real, [-0.3639702, 0.0], atol=1e-7)
    got = np.sort([np.tan(0.5 * check_pose(s, A, w, u, b, rho0)) for s in res.solutions])
    np.testing.assert_allclose(got, real, atol=1e-12)
    # base and platform are equilateral (similar triangles): two roots of the sextic are where det M = 0
    assert c.detail["roots_spurious"] == 2 and c.detail["degree"] == 6 and c.detail["circular_factors"] == 1
    assert "every root accounted for: 2 real, 2 complex (1 conjugate pair), 2 where det M = 0" in c.certificate


def test_solve_all_says_closed_form_in_text_and_json(capsys):
    args = ["solve", str(BUNDLED), "--all", "--set", "leg1,leg2,leg3=0"]
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "all 2 assembly modes (certified: closed form, a polynomial of degree 6 in tan(phi/2)" in text
    assert "2 more solutions are complex" in text
    assert main(args + ["--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["method"] == METHOD and d["complete"] is True
    m = d["modes"]
    assert (m["real"], m["complex"], m["method"]) == (2, 2, METHOD)
    assert m["certificate_check"]["checked"] and m["certificate_check"]["accounted"] == 6
    assert len(d["solutions"]) == 2


def test_a_general_3rpr_with_six_real_modes(tmp_path):
    """Innocenti & Parenti-Castelli's 3-RPR (tests/loci_robots.py) at leg lengths 14.98, 15.38, 12 (the
    published units; here m / 100): all six roots of its sextic real (rpr3_polynomial, independent)."""
    text, rho0 = rpr3()
    rho = np.array([14.98, 15.38, 12.0]) / 100
    poly = rpr3_polynomial(rho)
    want = np.sort([t.real for t in poly.roots() if abs(t.imag) < 1e-9])
    assert len(want) == 6
    (tmp_path / "r.urdf").write_text(text)
    solver = PositionSolver(screwkin.load(tmp_path / "r.urdf"))
    res = solver.solve({f"leg{k + 1}": rho[k] - rho0[k] for k in range(3)})
    c = res.modes
    assert c.complete and c.method == METHOD and (c.real, c.complex) == (6, 0)
    c0, s0 = np.cos(RPR_HOME[1]), np.sin(RPR_HOME[1])
    B = RPR_HOME[0] + RPR_PLATFORM @ np.array([[c0, -s0], [s0, c0]]).T
    w = B - RPR_BASE  # each leg's end at slide 0; its axis along it
    got = np.sort([np.tan(0.5 * (RPR_HOME[1] + check_pose(s, RPR_BASE, w, w / rho0[:, None], B - B[0], rho0)))
                   for s in res.solutions])
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-10)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_random_3rpr_counts_as_the_independent_polynomial(seed, tmp_path):
    rng = np.random.default_rng(seed)
    base = rng.uniform(-0.2, 0.2, (3, 2))
    platform = rng.uniform(-0.1, 0.1, (3, 2))
    platform -= platform[0]
    home = (rng.uniform(-0.05, 0.05, 2), rng.uniform(-np.pi, np.pi))
    text, rho0 = rpr3(base, platform, home)
    (tmp_path / "r.urdf").write_text(text)
    solver = PositionSolver(screwkin.load(tmp_path / "r.urdf"))
    R0 = rot(home[1])
    B = home[0] + platform @ R0.T
    for trial in range(3):  # the drawn lengths (the drawn pose among the modes), then others
        rho = rho0 * (rng.uniform(0.8, 1.25, 3) if trial else 1.0)
        roots, _ = genuine_roots(base, B - B[0], rho)  # phi from the drawn pose
        real = np.sort(roots[np.abs(roots.imag) < 1e-9].real)
        got = planar_poses(base, B - B[0], rho ** 2)
        assert not isinstance(got, str) and not got.unexplained
        assert (len(got.real), len(got.complex)) == (len(real), len(roots) - len(real))
        assert len(real) or trial
        if not len(real):  # none real: said so, certified
            with pytest.raises(AssemblyError, match=f"none of the {len(roots)} complex solutions is real "
                                                    r"\(certified: closed form, a polynomial of degree 6"):
                solver.solve({f"leg{k + 1}": rho[k] - rho0[k] for k in range(3)})
            continue
        res = solver.solve({f"leg{k + 1}": rho[k] - rho0[k] for k in range(3)})
        assert res.modes.complete and res.modes.method == METHOD, res.modes
        w = B - base
        ts = np.sort([np.tan(0.5 * check_pose(s, base, w, w / rho0[:, None], B - B[0], rho0)) for s in res.solutions])
        np.testing.assert_allclose(ts, real, rtol=1e-8, atol=1e-10)


def test_degenerate_geometries_are_said_not_counted():
    # three legs from one ground point to one platform point: the platform turns freely (P = 0 identically)
    why = planar_poses(np.zeros((3, 2)), np.zeros((3, 2)), np.ones(3))
    assert isinstance(why, str) and "vanishes identically" in why
    # congruent triangles and equal legs: at phi = 0 every translation on a circle is a pose (a continuum)
    tri = np.array([[0.0, 0.0], [1.0, 0.0], [0.3, 0.8]])
    got = planar_poses(tri, tri, np.ones(3))
    assert got.unexplained and "continuum" in got.unexplained[0]
    # congruent triangles, unequal legs: 4 real poses (counted by brute force), 2 roots where M = 0 at phi = 0
    got = planar_poses(tri, tri, np.array([1.90260864, 1.72378033, 0.50410775]))
    assert not got.unexplained and (len(got.real), len(got.complex), got.spurious) == (4, 0, 2)


@pytest.mark.slow
@pytest.mark.parametrize("which", ["bundled", "innocenti"])
def test_the_homotopy_finds_the_same_modes(which, tmp_path):
    if which == "bundled":
        solver, values = PositionSolver(screwkin.load(BUNDLED)), {"leg1": 0.0, "leg2": 0.0, "leg3": 0.0}
    else:
        text, rho0 = rpr3()
        (tmp_path / "r.urdf").write_text(text)
        solver = PositionSolver(screwkin.load(tmp_path / "r.urdf"))
        rho = np.array([14.98, 15.38, 12.0]) / 100
        values = {f"leg{k + 1}": rho[k] - rho0[k] for k in range(3)}
    closed = certified.planar_closed_form(solver, values)
    homotopy = certified.certified_modes(solver, values)
    assert not isinstance(closed, str) and not isinstance(homotopy, str)
    c, h = closed.count, homotopy.count
    assert (c.real, c.complex) == (h.real, h.complex), (c, h)
    tol = 1e-6 * max(solver.mech.length, 1.0)
    A = [solver.signature(m[0]) for m in closed.modes]
    H = [solver.signature(m[0]) for m in homotopy.modes]
    assert all(min(np.abs(x - y).max() for y in H) < tol for x in A)
    assert all(min(np.abs(x - y).max() for y in A) < tol for x in H)


@pytest.mark.slow  # about 4 s: the loci's tracing
def test_map_regions_count_the_modes_in_closed_form(capsys):
    """Each region of the bundled 3-RPR's (leg2, leg3) map is counted by the closed form, certain, its count
    the real poses of the independent polynomial at its sample (none real: certain too)."""
    A, w, u, b = legs_of(BUNDLED)
    rho0 = np.linalg.norm(w, axis=1)
    assert main(["map", str(BUNDLED), "--x", "leg2=0.15:-0.08:12", "--y", "leg3=0.15:-0.08:12", "--set", "leg1=0",
                 "--loci", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["regions"]
    for r in d["regions"]:
        roots, _ = genuine_roots(A, b - b[0], rho0 + np.array([0.0, *r["sample"]]))
        assert r["certain"] and r["modes"] == int(np.sum(np.abs(roots.imag) < 1e-9)), r
        assert r["how"] == METHOD if r["modes"] else "every solution is complex (certified)" in r["how"]


def test_at_a_fold_two_poses_meet_in_one_double_root(tmp_path):
    """Innocenti's 3-RPR at rho1, rho2 = 14.98, 15.38 with rho3 where two real roots of the independent
    sextic meet (bisected between 4 and 6 real roots): 5 real modes, one a double root (simple False,
    singular); a little to either side, 4 real and 2 complex, or 6 real -- all simple."""
    text, rho0 = rpr3()
    (tmp_path / "r.urdf").write_text(text)
    solver = PositionSolver(screwkin.load(tmp_path / "r.urdf"))

    def real_roots(r3):
        return int(sum(abs(t.imag) < 1e-7 for t in rpr3_polynomial(np.array([0.1498, 0.1538, r3])).roots()))

    lo, hi = 0.11, 0.116
    assert (real_roots(lo), real_roots(hi)) == (4, 6)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if real_roots(mid) == 4 else (lo, mid)

    def solve(r3):
        rho = np.array([0.1498, 0.1538, r3])
        return solver.solve({f"leg{k + 1}": rho[k] - rho0[k] for k in range(3)})

    res = solve(lo)
    assert res.method == METHOD and (res.modes.real, res.modes.complex) == (5, 0) and res.modes.complete
    (double,) = [s for s in res.solutions if s.simple is False]
    assert double.singular and double.residual < 1e-12
    assert res.modes.detail["multiple_poses"] == 1 and "(5 poses, some multiple)" in res.modes.certificate
    for r3, want in ((lo - 1e-7, (4, 2)), (hi + 1e-7, (6, 0))):
        res = solve(r3)
        assert (res.modes.real, res.modes.complex) == want and all(s.simple is not False for s in res.solutions)

"""A serial 3R's workspace section (issue 44): its cusps against the triple roots of the independent
inverse-kinematics quartic, each region's count of IK solutions against the quartic's real roots, and the
cuspidal verdict against Baili, Wenger & Chablat's orthogonal 3R family: d2 = 1, d3 = 2, d4 = 1.5, r2 = 1,
r3 = 0 is cuspidal (Wenger's example), r2 = r3 = 0 is not (det J = d4 (d2 + d3 c2)(d3 + d4 c3) s3, its
posture factors' signs tell the four solutions apart), d4 = r3 = 0 leaves the point on the third axis (det J
identically zero: no verdict)."""

import json
import re

import numpy as np
import pytest
from conftest import screwkin_cli
from loci_robots import orthogonal_3r, orthogonal_3r_quartic, orthogonal_3r_quartic_coefficients

import screwkin
from screwkin.analysis.singularities.section import trace_section

CUSPIDAL = (1.0, 2.0, 1.5, 1.0, 0.0)
POSTURES = (1.0, 2.0, 1.5, 0.0, 0.0)
FLAT = (1.0, 2.0, 0.0, 1.0, 0.0)


def _load(tmp_path, params, name):
    path = tmp_path / f"{name}.urdf"
    path.write_text(orthogonal_3r(*params))
    return path, screwkin.load(path)


def _real_roots(params, x, z):
    """The real roots of the independent quartic in t = tan(theta3 / 2) (numpy), and the nearest three's
    spread."""
    r = orthogonal_3r_quartic(*params, x, z).roots()
    real = [v.real for v in r if abs(v.imag) < 1e-6 * max(1.0, abs(v))]
    spread = min(max(abs(a - b) for a in g for b in g)
                 for g in [[r[i], r[j], r[k]] for i in range(4) for j in range(i + 1, 4) for k in range(j + 1, 4)])
    return real, spread


def _quartic_cusp(params, x, z):
    """The cusp near (x, z) located independently: Newton on (P, P', P'') = 0 in (x, z, t), P the quartic."""
    def F(v):
        P = orthogonal_3r_quartic(*params, v[0], v[1])
        return np.array([P(v[2]), P.deriv(1)(v[2]), P.deriv(2)(v[2])])

    r = orthogonal_3r_quartic(*params, x, z).roots()
    t = min(r, key=lambda a: np.sort(np.abs(r - a))[2]).real
    v = np.array([x, z, t])
    for _ in range(50):
        J = np.column_stack([(F(v + e) - F(v - e)) / 2e-7 for e in np.eye(3) * 1e-7])
        step = np.linalg.solve(J, -F(v))
        v = v + step
        if np.abs(step).max() < 1e-14:
            break
    return v


@pytest.mark.slow
def test_the_cuspidal_orthogonal_3r_is_cuspidal_with_cusps_at_the_quartics_triple_roots(tmp_path):
    _, mech = _load(tmp_path, CUSPIDAL, "o3r_cusp")
    grid = np.linspace(-5, 5, 41)
    sec = trace_section(mech, "tool", "x", grid, "z", grid, 0.0, samples=200)
    assert sec.cuspidal is True and sec.generic is True, sec.why
    assert "one aspect holds both" in sec.why
    assert len(sec.loci.cusps) == 8
    errors = []
    for (x, z), _ in sec.loci.cusps:
        _, spread = _real_roots(CUSPIDAL, x, z)
        assert spread < 1e-3
        X, Z, _ = _quartic_cusp(CUSPIDAL, x, z)
        errors.append(max(abs(X - x), abs(Z - z)))
    assert max(errors) < 1e-8, errors
    # every region's count: the quartic's real roots at its sample (the box's outside: none)
    assert {r.modes for r in sec.regions.regions} == {0, 2, 4}
    for r in sec.regions.regions:
        real, _ = _real_roots(CUSPIDAL, *r.sample)
        assert r.modes == len(real) and r.certain, r
    # every node of a region (a share of them): the same count as its sample, by the quartic
    for k, r in enumerate(sec.regions.regions):
        J, I = np.nonzero(sec.regions.labels == k + 1)
        for j, i in list(zip(J, I))[:: max(1, len(J) // 40)]:
            real, spread = _real_roots(CUSPIDAL, grid[i], grid[j])
            assert len(real) == r.modes, (grid[i], grid[j], r)
    # the nodes: where the curves meet on the first axis (x = 0, a self-motion), no other
    assert all(abs(x) < 1e-3 for (x, _), _ in sec.loci.nodes), sec.loci.nodes
    # the certificate: every component and every cusp, the plane holding the first axis (a tube about it)
    assert sec.loci.complete and sec.loci.cusps_complete, sec.loci.how
    assert "the plane holds the first axis" in sec.loci.how and "8 cusps" in sec.loci.how
    _witnesses_are_double_roots(mech, 0.0, 5.0)


def _witnesses_are_double_roots(mech, level, half):
    """Each witness of the certificate is a singular point of the section: the independent quartic at the
    point's distance from the first axis has a double real root there."""
    from screwkin.analysis.singularities.cuspidal import arm3r
    from screwkin.analysis.singularities.section import SectionSystem
    from screwkin.analysis.singularities.section_witness import section_witnesses

    sys = SectionSystem(mech, "tool", 0, 2, level, {})
    arm, _ = arm3r(mech, sys.fid, sys.free, mech.neutral())
    w = section_witnesses(arm, (0, 2), 1, level, ((-half, half), (-half, half)))
    assert w.certified and w.points, w.how
    for wt in w.points:
        x, z = wt.xy
        P = orthogonal_3r_quartic(*CUSPIDAL, np.hypot(x, level), z)
        scale = np.abs(P.coef).max()
        r = P.roots()
        t = r[np.argmin(np.abs(P.deriv()(r)) + np.abs(P(r)))]
        assert abs(t.imag) < 1e-4 and abs(P(t.real)) < 1e-9 * scale and abs(P.deriv()(t.real)) < 1e-6 * scale, wt
    return w


def test_a_section_off_the_first_axis_is_certified_complete_against_the_independent_quartic(tmp_path):
    """y = 0.7, a plane the first axis (z) does not lie in: the arm turns about z, so the solutions at
    (x, 0.7, z) are those at (hypot(x, 0.7), 0, z) turned -- the independent quartic counts them.  The trace
    is proved complete; every change of that count between neighbours of a 161 x 161 grid has a traced curve
    within a cell and a half; every certified cusp is a triple root (Newton on P = P' = P'' = 0, to 1e-8)."""
    _, mech = _load(tmp_path, CUSPIDAL, "o3r_off")
    level, grid = 0.7, np.linspace(-5, 5, 31)
    sec = trace_section(mech, "tool", "x", grid, "z", grid, level, samples=100, count=False)
    assert sec.loci.complete and sec.loci.cusps_complete, sec.loci.how
    assert "the first joint's circle touching the plane" in sec.loci.how
    assert len(sec.loci.cusps) == 8
    for (x, z), _ in sec.loci.cusps:
        R, Z, _ = _quartic_cusp(CUSPIDAL, np.hypot(x, level), z)
        assert abs(R - np.hypot(x, level)) < 1e-8 and abs(Z - z) < 1e-8
    w = _witnesses_are_double_roots(mech, level, 5.0)
    assert {p.system for p in w.points} >= {"t2 = 0 or pi", "circle touching"}
    assert _every_count_change_is_traced(sec, level, (-5, 5), (-5, 5), 161)


def _every_count_change_is_traced(sec, level, xr, zr, n):
    """Every change of the independent quartic's real-root count between neighbours of an n x n grid of the
    box (at (hypot(x, level), 0, z): the arm turns about z) has a traced curve within a cell and a half."""
    xs, zs = np.linspace(*xr, n), np.linspace(*zr, n)
    X, Z = np.meshgrid(xs, zs, indexing="ij")
    A = np.moveaxis(orthogonal_3r_quartic_coefficients(*CUSPIDAL, np.hypot(X, level), Z), 0, -1).reshape(-1, 5)
    M = np.zeros((len(A), 4, 4))  # companion matrices: the quartic's roots as eigenvalues (numpy)
    M[:, 1:, :-1] = np.eye(3)
    M[:, :, -1] = -A[:, :4] / A[:, 4:]
    r = np.linalg.eigvals(M)
    counts = (np.abs(r.imag) < 1e-6 * np.maximum(1.0, np.abs(r))).sum(axis=1).reshape(X.shape)
    u = np.linspace(0, 1, 20, endpoint=False)[:, None, None]  # the traced polylines, densely
    pts = np.vstack([(P[:-1] + u * np.diff(P, axis=0)).reshape(-1, 2) for P in (lc.points for lc in sec.loci.loci)]
                    or [np.full((1, 2), np.inf)])
    cell = max(xs[1] - xs[0], zs[1] - zs[0])
    changes = [((xs[i] + xs[i + di]) / 2, (zs[j] + zs[j + dj]) / 2)
               for di, dj in ((1, 0), (0, 1)) for i in range(n - di) for j in range(n - dj)
               if counts[i, j] != counts[i + di, j + dj]]
    far = [c for c in changes if np.abs(pts - c).max(axis=1).min() > 1.5 * cell]
    assert not far, far[:5]
    return changes


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(1, 9))
def test_wherever_a_random_section_is_certified_the_independent_count_agrees(tmp_path, seed):
    """Random planes y = level and boxes: where the trace is claimed complete, no change of the independent
    quartic's count is left without a traced curve; where it is not, the reason is said."""
    rng = np.random.default_rng(seed)
    level = float(rng.choice([0.0, rng.uniform(-1.5, 1.5)]))
    x0, z0 = rng.uniform(-5, 2, 2)
    xr, zr = (x0, x0 + rng.uniform(1, 3)), (z0, z0 + rng.uniform(1, 3))
    _, mech = _load(tmp_path, CUSPIDAL, f"o3r_rand{seed}")
    sec = trace_section(mech, "tool", "x", np.linspace(*xr, 21), "z", np.linspace(*zr, 21), level, samples=100,
                        count=False)
    if not sec.loci.complete:
        assert "no certificate" in sec.loci.how or "on no traced curve" in sec.loci.how, sec.loci.how
        return
    _every_count_change_is_traced(sec, level, xr, zr, 121)
    for (x, z), _ in sec.loci.cusps:
        R, Z, _ = _quartic_cusp(CUSPIDAL, np.hypot(x, level), z)
        assert abs(R - np.hypot(x, level)) < 1e-8 and abs(Z - z) < 1e-8


def test_a_non_generic_arm_gets_no_section_certificate(tmp_path):
    """r2 = 0: det J = d4 (d2 + d3 c2)(d3 + d4 c3) s3 factors, its curves cross: no certificate, said."""
    from screwkin.analysis.singularities.cuspidal import arm3r
    from screwkin.analysis.singularities.section import SectionSystem
    from screwkin.analysis.singularities.section_witness import section_witnesses

    _, mech = _load(tmp_path, POSTURES, "o3r_nocert")
    sys = SectionSystem(mech, "tool", 0, 2, 0.0, {})
    arm, _ = arm3r(mech, sys.fid, sys.free, mech.neutral())
    w = section_witnesses(arm, (0, 2), 1, 0.0, ((-5, 5), (-5, 5)))
    assert not w.certified and w.cusps is None and "singular point" in w.how


@pytest.mark.slow
def test_the_orthogonal_3r_with_r2_zero_is_not_cuspidal_its_postures_told_by_det_j_factors(tmp_path):
    _, mech = _load(tmp_path, POSTURES, "o3r_postures")
    grid = np.linspace(-5, 5, 21)
    sec = trace_section(mech, "tool", "x", grid, "z", grid, 0.0, samples=100)
    assert sec.cuspidal is False and sec.generic is False, sec.why
    assert "not generic" in sec.why
    # the trace reverses where its factors' curves meet: four IK solutions there (a quadruple root of the
    # quartic, theta3 = 0 twice over), not three -- no cusp
    assert not sec.loci.cusps
    note = next(n for n in sec.loci.notes if "not cusps" in n)


    points = re.findall(r"\((-?[0-9.e+-]+), (-?[0-9.e+-]+)\)", note)
    assert points
    for x, z in points:
        r = orthogonal_3r_quartic(*POSTURES, float(x), float(z)).roots()
        assert np.abs(r - r.mean()).max() < 1e-2, r  # a quadruple root spreads as the 4th root of an error
    # its curves are traced twice (the +-theta3 branches meet the same points): their meetings are no nodes
    assert all(abs(x) < 1e-3 for (x, _), _ in sec.loci.nodes), sec.loci.nodes
    for r in sec.regions.regions:
        real, _ = _real_roots(POSTURES, *r.sample)
        assert r.modes == len(real), r
    # independently: at every point of a grid the IK solutions (the quartic's roots, then theta2) have
    # distinct sign patterns of the factors (d2 + d3 c2) and s3 of det J -- no two can meet without a
    # singularity, the robot is not cuspidal (Wenger 1997)
    d2, d3, d4, _, _ = POSTURES
    for x in np.linspace(-4.4, 4.4, 23):
        for z in np.linspace(-3.4, 3.4, 19):
            real, _ = _real_roots(POSTURES, x, z)
            signs = set()
            for t in real:
                t3 = 2 * np.arctan(t)
                for t2 in _theta2(POSTURES, t3, z):
                    p = _position(POSTURES, 0.0, t2, t3)
                    if abs(np.hypot(p[0], p[1]) - abs(x)) < 1e-7:
                        signs.add((np.sign(d2 + d3 * np.cos(t2)), np.sign(np.sin(t3))))
            # one sign pattern per solution
            assert len(signs) == len(real), (x, z, len(signs), len(real))


def _theta2(params, t3, z):
    """theta2 placing the point at height z for this theta3: the height is A cos t2 + B sin t2 + C."""
    h = [_position(params, 0.0, a, t3)[2] for a in (0.0, np.pi / 2, np.pi)]
    C = (h[0] + h[2]) / 2
    A, B = h[0] - C, h[1] - C
    c = (z - C) / np.hypot(A, B)
    if abs(c) > 1:
        return []
    return [np.arctan2(B, A) + s * np.arccos(c) for s in (1, -1)]


def _position(params, t1, t2, t3):
    """The orthogonal 3R's tool point (numpy, modified DH as in loci_robots.orthogonal_3r)."""
    d2, d3, d4, r2, r3 = params

    def T(xyz, roll, th):
        cr, sr, ct, st = np.cos(roll), np.sin(roll), np.cos(th), np.sin(th)
        M = np.eye(4)
        M[:3, :3] = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]]) @ np.array([[ct, -st, 0], [st, ct, 0], [0, 0, 1]])
        M[:3, 3] = xyz
        return M

    M = T((0, 0, 0), 0, t1) @ T((d2, 0, 0), -np.pi / 2, t2) @ T((d3, 0, r2), np.pi / 2, t3)
    return (M @ np.array([d4, 0, r3, 1.0]))[:3]


@pytest.mark.slow
def test_the_bundled_arm_with_its_wrist_held_is_not_cuspidal():
    """robots/arm_6r.urdf's first three joints (axes 2 and 3 parallel, axis 2 off axis 1 by 0.05 m: a
    PUMA-like arm) moving the flange with the wrist held: a 3R with two parallel axes is not cuspidal (Wenger
    1997: its inverse kinematics reduces to quadratics, det J to an elbow and a shoulder factor); its det J
    zero set crosses itself (not generic), the wedges at the crossings thinner than the grid near them."""
    from pathlib import Path

    mech = screwkin.load(Path(__file__).resolve().parents[3] / "robots" / "arm_6r.urdf")
    xs, ys = np.linspace(-1.5, 1.5, 21), np.linspace(-1, 2, 21)
    sec = trace_section(mech, "flange", "x", xs, "z", ys, 0.0, {"joint4": 0.0, "joint5": 0.3, "joint6": 0.0},
                        samples=100)
    assert sec.cuspidal is False and sec.generic is False and sec.aspects == 4, sec.why


def test_a_point_on_the_third_axis_has_no_verdict(tmp_path):
    _, mech = _load(tmp_path, FLAT, "o3r_flat")
    grid = np.linspace(-4, 4, 9)
    sec = trace_section(mech, "tool", "x", grid, "z", grid, 0.0, samples=20, count=False)
    assert sec.cuspidal is None and "zero everywhere" in sec.why


def test_closed_form_ik_counts_match_the_independent_quartic(tmp_path):
    """The region counter (the position stage of Pieper's closed form) against numpy's roots of the quartic
    at points of the plane y = 0."""
    from screwkin.analysis.singularities.cuspidal import arm3r, point_ik
    from screwkin.analysis.singularities.section import SectionSystem

    _, mech = _load(tmp_path, CUSPIDAL, "o3r_ik")
    sys = SectionSystem(mech, "tool", 0, 2, 0.0, {})
    arm, why = arm3r(mech, sys.fid, sys.free, mech.neutral())
    assert arm is not None, why
    for x in np.linspace(-4.3, 4.3, 9):
        for z in np.linspace(-3.3, 3.3, 9):
            real, spread = _real_roots(CUSPIDAL, x, z)
            if spread < 1e-3:
                continue  # next to a cusp
            sols, _ = point_ik(arm, np.array([x, 0.0, z]))
            assert len(sols) == len(real), (x, z)
            for t in sols:  # each places the point
                p = _position(CUSPIDAL, *t)
                assert np.linalg.norm(p - [x, 0, z]) < 1e-9


@pytest.mark.slow
def test_map_of_a_workspace_section_json(tmp_path):
    path, _ = _load(tmp_path, CUSPIDAL, "o3r_cli")
    png = tmp_path / "section.png"
    p = screwkin_cli("map", str(path), "--output", "tool", "--x", "x=-5000mm:5000mm:31", "--y", "z=-5:5:31",
                     "--loci", "--json", "--png", str(png))
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    assert d["cuspidal"] is True and "aspect" in d["cuspidal_rests_on"]
    assert d["section"]["held"] == {"y": 0.0} and "y held at 0 m" in d["section_notes"][0]
    assert len(d["cusps"]) == 8 and d["complete"] is True and d["cusps_complete"] is True
    for x, z in d["cusps"]:  # x in mm as typed
        assert abs(x) > 1000 and _real_roots(CUSPIDAL, x / 1000, z)[1] < 1e-3
    for r in d["regions"]:
        assert r["modes"] == len(_real_roots(CUSPIDAL, r["sample"][0] / 1000, r["sample"][1])[0])
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_map_section_usage_errors(tmp_path):
    path, _ = _load(tmp_path, FLAT, "o3r_usage")
    p = screwkin_cli("map", str(path), "--x", "x=-1:1:5", "--y", "z=-1:1:5", "--loci")
    assert p.returncode == 2 and "--output" in p.stderr and "Traceback" not in p.stderr
    p = screwkin_cli("map", str(path), "--output", "tool", "--x", "x=-1:1:5", "--y", "theta2=-1:1:5", "--loci")
    assert p.returncode == 2 and "coordinates" in p.stderr
    p = screwkin_cli("map", str(path), "--output", "tool", "--x", "x=-1:1:5", "--y", "z=-1:1:5")
    assert p.returncode == 2 and "--loci" in p.stderr
    p = screwkin_cli("map", str(path), "--output", "tool", "--x", "x=-1:1:5", "--y", "z=-1:1:5", "--loci",
                     "--set", "x=0")
    assert p.returncode == 2 and "held coordinate is y" in p.stderr
    p = screwkin_cli("map", str(path), "--output", "tool", "--x", "x=-1:1:5", "--y", "z=-1:1:5", "--loci", "--mode", "2")
    assert p.returncode == 2 and "--mode" in p.stderr and "Traceback" not in p.stderr


@pytest.mark.slow
def test_map_section_of_a_point_on_the_third_axis_says_cuspidal_null(tmp_path):
    path, _ = _load(tmp_path, FLAT, "o3r_null")
    p = screwkin_cli("map", str(path), "--output", "tool", "--x", "x=-1:1:5", "--y", "z=-1:1:5", "--loci", "--json",
                     "--no-regions")
    assert p.returncode == 0, p.stderr
    assert json.loads(p.stdout)["cuspidal"] is None


def test_sections_the_certificate_does_not_take_say_why(tmp_path):
    """The plane z = 0 is square to the first axis (z): the curve there is circles about it; the box's edge
    x = 0 of the plane y = 0 lies on the first axis, where the point stays for a whole turn of joint 1."""
    from screwkin.analysis.singularities.cuspidal import arm3r
    from screwkin.analysis.singularities.section import SectionSystem
    from screwkin.analysis.singularities.section_witness import section_witnesses

    _, mech = _load(tmp_path, CUSPIDAL, "o3r_why")
    sys = SectionSystem(mech, "tool", 0, 1, 0.0, {})
    arm, _ = arm3r(mech, sys.fid, sys.free, mech.neutral())
    w = section_witnesses(arm, (0, 1), 2, 0.0, ((-5, 5), (-5, 5)))
    assert not w.certified and "square to the first axis" in w.how
    w = section_witnesses(arm, (0, 2), 1, 0.0, ((0, 5), (-5, 5)))
    assert not w.certified and "edge x = 0 m lies on the first axis" in w.how

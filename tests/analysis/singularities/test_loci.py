"""Singular loci traced in the plane of two inputs, their cusps, nodes and regions (issue 44), against closed
forms: the five-bar's actuator and serial sets, and the 3-RPR's cusps as triple roots of its forward-kinematics
polynomial (built independently with numpy in tests/loci_robots.py)."""

import json

import numpy as np
import pinocchio as pin
import pytest
from conftest import screwkin_cli
from loci_robots import FIVE_BAR, RPR_BASE, five_bar, rpr3, rpr3_cusp, rpr3_polynomial
from numpy.polynomial import Polynomial

import screwkin
from screwkin.analysis.position.connect import loop, wedge_direction
from screwkin.analysis.singularities.loci import trace_loci
from screwkin.analysis.singularities.regions import regions

REL = 1e-9


@pytest.fixture(scope="module")
def five(tmp_path_factory):
    text, elbows = five_bar(**FIVE_BAR)
    path = tmp_path_factory.mktemp("loci") / "five_bar_loci.urdf"
    path.write_text(text)
    return path, elbows


def _five_bar_conditions(elbows, m1, m2):
    """The closed forms, relative: actuator -- the distal links collinear, |B1 B2| = b1 + b2 or |b1 - b2|;
    serial -- a leg stretched or folded, the tip on proximal i's line at a_i +- b_i from A_i and at b_j from
    B_j."""
    a1, a2, b1, b2 = (FIVE_BAR[k] for k in ("a1", "a2", "b1", "b2"))
    A1, A2, B1, B2 = elbows(m1, m2)
    d = np.linalg.norm(B2 - B1)
    actuator = [(d - (b1 + b2)) / (b1 + b2), (d - abs(b1 - b2)) / (b1 + b2)]
    u1, u2 = (B1 - A1) / a1, (B2 - A2) / a2
    serial = [(np.linalg.norm(A1 + c * u1 - B2) - b2) / b2 for c in (a1 + b1, a1 - b1)]
    serial += [(np.linalg.norm(A2 + c * u2 - B1) - b1) / b1 for c in (a2 + b2, a2 - b2)]
    return actuator, serial


def _dense(P, k=10):
    """The polyline P with k points on each segment (the traces' points are continuation steps apart)."""
    if len(P) < 2:
        return P
    w = np.arange(k) / k
    return np.vstack([P[i] + np.outer(w, P[i + 1] - P[i]) for i in range(len(P) - 1)] + [P[-1:]])


def _trace_five(five, n=41, regions_too=False):
    path, _ = five
    mech = screwkin.load(path)
    solver = screwkin.PositionSolver(mech)
    xs = ys = np.radians(np.linspace(-90, 90, n))
    traced = trace_loci(solver, "motor1", xs, "motor2", ys, {}, output="tip", point=True)
    cut = regions(solver, traced, "motor1", xs, "motor2", ys, {}) if regions_too else None
    return traced, cut, xs, ys


def test_five_bar_loci_points_satisfy_the_closed_forms_and_every_component_is_found(five):
    traced, _, xs, ys = _trace_five(five)
    _, elbows = five
    kinds = {lc.kind for lc in traced.loci}
    assert kinds == {"actuator", "serial"}
    for lc in traced.loci:
        assert len(lc.points) > 10
        for m1, m2 in lc.points:
            actuator, serial = _five_bar_conditions(elbows, m1, m2)
            assert min(abs(c) for c in (actuator if lc.kind == "actuator" else serial)) < REL, (lc.kind, m1, m2)
            assert xs[0] - 1e-12 <= m1 <= xs[-1] + 1e-12 and ys[0] - 1e-12 <= m2 <= ys[-1] + 1e-12
    # completeness against the closed forms: every sign change of a closed-form condition between neighbouring
    # nodes of a fine grid has a traced point of that kind within a cell
    fine = np.radians(np.linspace(-90, 90, 121))
    cell = fine[1] - fine[0]
    G = np.array([[np.concatenate(_five_bar_conditions(elbows, a, b)) for a in fine] for b in fine])
    for k in range(G.shape[2]):
        kind = "actuator" if k < 2 else "serial"
        pts = np.concatenate([_dense(lc.points) for lc in traced.loci if lc.kind == kind])
        g = G[:, :, k]
        for j, i, j2, i2 in [(j, i, j, i + 1) for j in range(121) for i in range(120)] + \
                            [(j, i, j + 1, i) for j in range(120) for i in range(121)]:
            if g[j, i] * g[j2, i2] < 0:
                mid = np.array([fine[i] + fine[i2], fine[j] + fine[j2]]) / 2
                assert np.abs(pts - mid).max(axis=1).min() < cell, (kind, k, np.degrees(mid))


def test_five_bar_regions_count_the_closed_form_modes(five):
    _, cut, xs, ys = _trace_five(five, n=41, regions_too=True)
    _, elbows = five
    b1, b2 = FIVE_BAR["b1"], FIVE_BAR["b2"]
    assert len(cut.regions) >= 4
    for r in cut.regions:
        _, _, B1, B2 = elbows(*r.sample)
        d = np.linalg.norm(B2 - B1)
        expected = 2 if abs(b1 - b2) < d < b1 + b2 else 0
        assert r.modes == expected, r
    # every node of a region on one side of the curves: the same number of modes as its sample (closed form)
    for k, r in enumerate(cut.regions):
        J, I = np.nonzero(cut.labels == k + 1)
        for j, i in list(zip(J, I))[:: max(1, len(J) // 25)]:
            _, _, B1, B2 = elbows(xs[i], ys[j])
            d = np.linalg.norm(B2 - B1)
            assert (2 if abs(b1 - b2) < d < b1 + b2 else 0) == r.modes


def test_map_loci_json_keeps_the_map_keys_and_answers_in_the_typed_units(five, tmp_path):
    path, elbows = five
    png = tmp_path / "loci.png"
    p = screwkin_cli("map", str(path), "--x", "motor1=-90deg:90deg:31", "--y", "motor2=-90deg:90deg:31",
                     "--loci", "--output", "tip", "--point", "--json", "--png", str(png))
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    for key in ("xs", "ys", "log10_sigma_min", "kind", "reached", "seams", "notes"):  # the map's own keys stay
        assert key in d
    assert d["complete"] is False and "seeds" in d["how"]
    assert {lc["kind"] for lc in d["loci"]} == {"actuator", "serial"}
    for lc in d["loci"]:
        for x, y in lc["points"]:  # degrees, as typed
            assert -90 - 1e-9 <= x <= 90 + 1e-9 and -90 - 1e-9 <= y <= 90 + 1e-9
            actuator, serial = _five_bar_conditions(elbows, np.radians(x), np.radians(y))
            assert min(abs(c) for c in (actuator if lc["kind"] == "actuator" else serial)) < 1e-8
    assert all(r["modes"] in (0, 2) for r in d["regions"])
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_map_loci_needs_the_other_inputs_held(tmp_path):
    text, _ = rpr3()
    path = tmp_path / "rpr3.urdf"
    path.write_text(text)
    p = screwkin_cli("map", str(path), "--x", "leg2=0:0.1:5", "--y", "leg3=0:0.1:5", "--set", "leg1=0", "--loci",
                     "--no-regions")
    assert p.returncode == 0, p.stderr
    p = screwkin_cli("map", str(path), "--x", "leg2=0:0.1:5", "--y", "leg3=0:0.1:5", "--loci")
    assert p.returncode == 2 and "leg1" in p.stderr and "Traceback" not in p.stderr


@pytest.fixture(scope="module")
def rpr(tmp_path_factory):
    """The 3-RPR of Innocenti & Parenti-Castelli (Zein, Wenger & Chablat 2008) in the section rho1 = 0.17 m
    (17 in the published units): (mech, solver, text, rho0, rho1, traced actuator loci in (rho2, rho3))."""
    text, rho0 = rpr3()
    path = tmp_path_factory.mktemp("rpr") / "rpr3.urdf"
    path.write_text(text)
    mech = screwkin.load(path)
    solver = screwkin.PositionSolver(mech)
    rho1 = 0.17
    xs, ys = np.linspace(0.02, 0.40, 41) - rho0[1], np.linspace(0.02, 0.40, 41) - rho0[2]
    traced = trace_loci(solver, "leg2", xs, "leg3", ys, {"leg1": rho1 - rho0[0]})
    return mech, solver, text, rho0, rho1, traced


def _platform_t(mech, q):
    """tan(phi / 2) of the platform's turn phi from its frame in RPR_PLATFORM: drawn at 30 deg, then turned
    by the planar revolutes base1 and wrist1 of the tree."""
    phi = np.radians(30.0) + q[mech.coordinate("base1").idx_q] + q[mech.coordinate("wrist1").idx_q]
    return np.tan(0.5 * phi)


@pytest.mark.slow
def test_3rpr_loci_have_concurrent_legs_and_cusps_that_are_triple_roots(rpr):
    """Each locus point with the three leg lines concurrent (the actuator singularity in closed form); each
    cusp where three of the polynomial's roots coincide, located to 1e-8 m by an independent Newton on
    P = P' = P'' = 0."""
    mech, _, text, rho0, rho1, traced = rpr
    assert traced.loci and {lc.kind for lc in traced.loci} == {"actuator"}
    base = [mech.coordinate(f"base{i}").idx_q for i in (1, 2, 3)]
    u0 = [np.array([float(v) for v in
                    text.split(f'name="leg{i}"')[1].split('axis xyz="')[1].split('"')[0].split()[:2]])
          for i in (1, 2, 3)]
    for lc in traced.loci:
        for q in lc.q[:: 5]:
            rows = []
            for i in range(3):  # the leg's line: through A_i along its base joint's turn of the drawn direction
                c, s = np.cos(q[base[i]]), np.sin(q[base[i]])
                d = np.array([c * u0[i][0] - s * u0[i][1], s * u0[i][0] + c * u0[i][1]])
                n = np.array([-d[1], d[0]])
                rows.append([n[0], n[1], n @ RPR_BASE[i] / 0.2])
            assert abs(np.linalg.det(np.array(rows))) < REL
    assert len(traced.cusps) >= 2
    for (x, y), _kind in traced.cusps:
        rho = (rho1, x + rho0[1], y + rho0[2])
        roots = rpr3_polynomial(rho).roots()
        t = min(roots, key=lambda z: np.sort(np.abs(roots - z))[2]).real  # the middle of the tightest three
        r2, r3, tc = rpr3_cusp(rho1, rho[1], rho[2], t)
        assert abs(r2 - rho[1]) < 1e-8 and abs(r3 - rho[2]) < 1e-8, (rho, r2, r3)
        P = rpr3_polynomial((rho1, r2, r3))
        # each derivative relative to the sum of its terms' sizes at tc: round-off is 1e-16 of that
        rel = [abs(D(tc)) / Polynomial(np.abs(D.coef))(abs(tc)) for D in (P, P.deriv(1), P.deriv(2), P.deriv(3))]
        assert max(rel[:3]) < 1e-9, rel  # a triple root
        assert rel[3] > 1e-4, rel  # and not a quadruple one


def _real_roots(rho):
    """The real roots of the independent polynomial (its factor 1 + t^2 aside) at the leg lengths rho."""
    q, _ = divmod(rpr3_polynomial(rho), Polynomial([1.0, 0.0, 1.0]))
    z = q.roots()
    return np.sort(z[np.abs(z.imag) < 1e-7 * (1 + np.abs(z))].real)


@pytest.mark.slow
def test_the_3rpr_workspace_boundary_in_the_corner_is_traced_from_the_box_edges(rpr):
    """The component that bounds the corner of the box where no mode assembles, from (0.02, 0.0503) to
    (0.1044, 0.02) m: no grid seed reaches it (the tracer missed it before the box's edges were walked).
    Across each of its ends, along the edge, the independent polynomial's real roots go from 0 to 2; along
    it, two of them coincide."""
    _, _, _, rho0, rho1, traced = rpr
    lo = (0.02 - rho0[1], 0.02 - rho0[2])
    corner = [lc for lc in traced.loci if {round(float(lc.points[k][a] - lo[a]), 9) for k in (0, -1) for a in (0, 1)}
              >= {0.0} and lc.points[:, 0].max() + rho0[1] < 0.12 and lc.points[:, 1].max() + rho0[2] < 0.06]
    assert len(corner) == 1, [lc.points[[0, -1]] + rho0[1:] for lc in traced.loci]
    P = corner[0].points + rho0[1:]
    ends = sorted([P[0], P[-1]], key=lambda p: p[0])
    assert abs(ends[0][0] - 0.02) < 1e-12 and abs(ends[1][1] - 0.02) < 1e-12
    for (x, y), along in ((ends[0], 1), (ends[1], 0)):
        d = np.array([0.0, 1e-4]) if along else np.array([1e-4, 0.0])
        counts = [len(_real_roots((rho1, *(np.array([x, y]) + s * d)))) for s in (-1, 1)]
        assert sorted(counts) == [0, 2], ((x, y), counts)
    for x, y in P[::3]:  # a double root splits by round-off into a near pair, real or complex
        q, _ = divmod(rpr3_polynomial((rho1, x, y)), Polynomial([1.0, 0.0, 1.0]))
        z = q.roots()
        gap = np.where(np.eye(len(z), dtype=bool), np.inf, np.abs(z[:, None] - z[None]))
        i, j = np.unravel_index(np.argmin(gap), gap.shape)
        assert gap[i, j] < 1e-6 * (1 + abs(z[i])) and abs((z[i] + z[j]).imag) < 1e-6, ((x, y), z)


@pytest.mark.slow
def test_a_loop_round_a_cusp_changes_the_3rpr_mode_without_a_singularity(rpr):
    """McAree & Daniel 1999, Zein, Wenger & Chablat 2008: from inside a cusp's wedge (three of the modes
    there are the cusp's), each outer one of the three, followed once round the cusp in one sense, comes
    back on another mode with the actuator measure away from zero all along; a loop of the same size round
    no cusp brings every mode back to itself.  Both ends are real roots of the independent polynomial."""
    mech, solver, _, rho0, rho1, traced = rpr
    fixed = {"leg1": rho1 - rho0[0]}
    (cx, cy), _ = traced.cusps[0]
    r = 0.004
    pts = np.concatenate([lc.points for lc in traced.loci])
    th = wedge_direction(pts, (cx, cy), r)
    start = (cx + r * np.cos(th), cy + r * np.sin(th))
    sols = solver.solve({"leg2": start[0], "leg3": start[1], **fixed}).solutions
    P = rpr3_polynomial((rho1, start[0] + rho0[1], start[1] + rho0[2]))
    changed = 0
    for sol in sols:
        for turn in (1, -1):
            L = loop(solver, "leg2", "leg3", fixed, (cx, cy), (r, r), sol.q, start=th, turn=turn)
            if L.regular and L.joined:
                changed += 1
                t0, t1 = _platform_t(mech, L.q[0]), _platform_t(mech, L.q[-1])
                for t in (t0, t1):  # real roots: the residual is round-off of the coefficients' size
                    assert abs(P(t)) < 1e-10 * np.linalg.norm(P.coef) * max(1.0, abs(t)) ** P.degree()
                assert abs(t0 - t1) > 1e-3  # another root: another assembly mode
                assert L.sigma_min > mech.tolerances.singular
    assert changed >= 2  # the two outer modes of the cusp, each in one sense
    # a loop round no cusp: every mode comes back
    far = (cx + 3 * r * np.cos(th + np.pi), cy + 3 * r * np.sin(th + np.pi))
    assert all(np.hypot(far[0] - p[0], far[1] - p[1]) > 2 * r for p, _ in traced.cusps)
    for sol in solver.solve({"leg2": far[0] + r, "leg3": far[1], **fixed}).solutions:
        L = loop(solver, "leg2", "leg3", fixed, far, (r, r), sol.q)
        assert not L.joined


@pytest.mark.slow
def test_map_connect_lists_the_mode_changes_round_a_3rpr_cusp(tmp_path):
    """map --loci --connect near one cusp of the 3-RPR section: the two outer modes of the cusp exchanged,
    one each way round, each loop's path closed (every point a real root of the independent polynomial)."""
    text, rho0 = rpr3()
    path = tmp_path / "rpr3.urdf"
    path.write_text(text)
    rho1 = 0.17
    x0, x1, y0, y1, held = (float(v) for v in (0.15 - rho0[1], 0.21 - rho0[1], 0.29 - rho0[2], 0.34 - rho0[2],
                                                rho1 - rho0[0]))
    p = screwkin_cli("map", str(path), "--x", f"leg2={x0!r}:{x1!r}:21", "--y", f"leg3={y0!r}:{y1!r}:21",
                     "--set", f"leg1={held!r}",
                     "--loci", "--connect", "--no-regions", "--json", timeout=900)
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    assert len(d["cusps"]) == 1 and d["connections_tried"] >= 6
    pairs = sorted(tuple(c["modes"]) for c in d["connections"])
    assert len(pairs) == 2 and pairs[0] == tuple(reversed(pairs[1])), pairs  # a -> c one way, c -> a the other
    assert {c["turn"] for c in d["connections"]} == {"clockwise", "counter-clockwise"}
    for c in d["connections"]:
        assert c["joined"] and c["sigma_min"] > 1e-4
        for point in c["path"]:
            rho2, rho3 = point["inputs"][0] + rho0[1], point["inputs"][1] + rho0[2]
            t = np.tan(0.5 * (np.radians(30.0) + point["joints"]["base1"] + point["joints"]["wrist1"]))
            P = rpr3_polynomial((rho1, rho2, rho3))
            assert abs(P(t)) < 1e-10 * np.linalg.norm(P.coef) * max(1.0, abs(t)) ** P.degree()


def test_map_loci_of_a_box_over_a_whole_turn(five):
    """A box over 0..360 deg (the solver's angles are in [-180, 180)): the seeds are taken the whole turn into
    it; the five-bar's inner curve |B1 B2| = b1 - b2 lies near motor1 = -60 deg, here 300 deg."""
    path, elbows = five
    p = screwkin_cli("map", str(path), "--x", "motor1=0deg:360deg:37", "--y", "motor2=90deg:-90deg:19", "--loci",
                     "--no-regions", "--json")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    closed = [lc for lc in d["loci"] if lc["closed"]]
    assert len(closed) == 1 and closed[0]["kind"] == "actuator"
    for x, y in closed[0]["points"]:
        assert 270 < x < 330
        actuator, _ = _five_bar_conditions(elbows, np.radians(x), np.radians(y))
        assert abs(actuator[1]) < 1e-8


@pytest.mark.slow
def test_a_cuspidal_orthogonal_3r_has_cusps_where_three_ik_solutions_meet(tmp_path):
    """The orthogonal 3R d2 = 1, d3 = 2, d4 = 1.5, r2 = 1, r3 = 0 (Baili, Wenger & Chablat's family; Wenger's
    cuspidal example): in the section y = 0 its serial singular curve has four cusps on each side of the
    first axis, each a triple root of the independent inverse-kinematics quartic; the robot is cuspidal."""
    from loci_robots import orthogonal_3r, orthogonal_3r_quartic

    from screwkin.analysis.singularities.section import trace_section

    params = (1.0, 2.0, 1.5, 1.0, 0.0)
    path = tmp_path / "o3r.urdf"
    path.write_text(orthogonal_3r(*params))
    mech = screwkin.load(path)
    grid = np.linspace(-5, 5, 41)
    sec = trace_section(mech, "tool", "x", grid, "z", grid, 0.0, samples=200)
    assert sec.cuspidal
    assert len(sec.loci.cusps) == 8
    assert sum(p[0] > 0 for p, _ in sec.loci.cusps) == 4
    for (x, z), _ in sec.loci.cusps:
        P = orthogonal_3r_quartic(*params, x, z)
        roots = P.roots()
        spread = min(max(abs(a - b) for a in g for b in g)
                     for g in [[roots[i], roots[j], roots[k]] for i in range(4) for j in range(i + 1, 4)
                               for k in range(j + 1, 4)])
        assert spread < 1e-3 * max(1.0, abs(roots).max())  # three roots together (a triple root, perturbed)
    for lc in sec.loci.loci:  # every point on the serial condition: J_p over the three joints singular
        for q in lc.q[:: 10]:
            Jp = pin.computeFrameJacobian(mech.model, mech.model.createData(), q, mech.model.getFrameId("tool"),
                                          pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)[:3]
            s = np.linalg.svd(Jp, compute_uv=False)
            assert s[-1] / s[0] < 1e-9

"""The certificate that every component of a 3-RPR's actuator locus in the box was traced
(analysis.singularities.loci_witness), against the forward-kinematics polynomial built independently with numpy
(tests/loci_robots.py): each witness where two of its real roots meet, the edge witnesses exactly where the
number of its real roots changes along the box's edges (an independent dense scan), and the curves found again
from the witnesses alone when the grid's seeds are too few."""

import numpy as np
import pytest
from conftest import ROBOTS
from loci_robots import FIVE_BAR, five_bar, rpr3, rpr3_cusp, rpr3_polynomial
from numpy.polynomial import Polynomial

import screwkin
from screwkin.analysis.singularities.loci import trace_loci
from screwkin.analysis.singularities.loci_witness import witnesses

RHO1, LO, HI = 0.17, 0.02, 0.40  # the section rho1 = 0.17 m, rho2 and rho3 from 0.02 to 0.40 m


@pytest.fixture(scope="module")
def rpr(tmp_path_factory):
    text, rho0 = rpr3()
    path = tmp_path_factory.mktemp("witness") / "rpr3.urdf"
    path.write_text(text)
    solver = screwkin.PositionSolver(screwkin.load(path))
    box = ((LO - rho0[1], HI - rho0[1]), (LO - rho0[2], HI - rho0[2]))
    fixed = {"leg1": RHO1 - rho0[0]}
    return solver, rho0, box, fixed, witnesses(solver, "leg2", "leg3", box, fixed)


def _reduced(rho):
    q, _ = divmod(rpr3_polynomial(rho), Polynomial([1.0, 0.0, 1.0]))
    return q


def _real_count(rho) -> int:
    z = _reduced(rho).roots()
    return int(np.sum(np.abs(z.imag) < 1e-7 * (1 + np.abs(z))))


@pytest.mark.slow
def test_each_witness_is_where_two_modes_of_the_independent_polynomial_meet(rpr):
    _, rho0, _, _, w = rpr
    assert w.certified and "no certificate" not in w.how
    assert len(w.points) == 22
    for p in w.points:
        rho = (RHO1, p.xy[0] + rho0[1], p.xy[1] + rho0[2])
        P = _reduced(rho)
        t = np.tan(0.5 * (p.angles[1] + np.radians(30.0)))  # the polynomial's angle: from the platform's frame
        # P and P' vanish there (relative to their largest coefficient times (1 + |t|)^degree): a double root
        for D in (P, P.deriv(1)):
            assert abs(D(t)) <= 1e-9 * np.abs(D.coef).max() * (1 + abs(t)) ** D.degree(), (p.system, rho, t)


@pytest.mark.slow
def test_the_edge_witnesses_are_where_the_mode_count_changes_along_the_edges(rpr):
    """A dense scan of each edge with the independent polynomial: the real roots' count changes at as many
    places as there are edge witnesses, each within a scan step of one."""
    _, rho0, _, _, w = rpr
    edge = [p for p in w.points if p.system == "edge"]
    s = np.linspace(LO, HI, 1201)
    changes = []
    for axis in (0, 1):
        for bound in (LO, HI):
            counts = []
            for v in s:
                r2, r3 = (bound, v) if axis == 0 else (v, bound)
                counts.append(_real_count((RHO1, r2, r3)))
            for k in np.nonzero(np.diff(counts))[0]:
                changes.append((axis, bound, 0.5 * (s[k] + s[k + 1])))
    assert len(changes) == len(edge) == 10
    step = s[1] - s[0]
    for axis, bound, v in changes:
        hit = [p for p in edge if abs(p.xy[axis] + rho0[1 + axis] - bound) < 1e-9
               and abs(p.xy[1 - axis] + rho0[2 - axis] - v) <= step]
        assert len(hit) == 1, (axis, bound, v)


@pytest.mark.slow
def test_the_witnesses_alone_find_every_curve_and_the_trace_is_complete(rpr):
    """With a 2 x 2 grid of seeds (the box's corners), the grid's seeds miss curves; the witnesses seed them:
    the same five curves, with the same ends on the box's edges, as with the 9 x 9 grid, and complete."""
    solver, rho0, box, fixed, _ = rpr
    xs, ys = np.linspace(*box[0], 41), np.linspace(*box[1], 41)
    fine = trace_loci(solver, "leg2", xs, "leg3", ys, fixed)
    coarse = trace_loci(solver, "leg2", xs, "leg3", ys, fixed, grid=2)
    for traced in (fine, coarse):
        assert traced.complete and "Krawczyk" in traced.how and "Complete:" in traced.how
        assert len(traced.loci) == 5
        assert traced.cusps_complete and len(traced.cusps) == 6 and "Cusps complete: 6 cusps" in traced.how

    def ends(traced):
        return sorted(tuple(np.round(p, 9)) for lc in traced.loci for p in (lc.points[0], lc.points[-1]))
    np.testing.assert_allclose(ends(fine), ends(coarse), atol=1e-9)


@pytest.mark.slow
def test_the_certified_cusps_are_the_triple_roots_of_the_independent_polynomial(rpr):
    """Six cusps in the box, each where three real roots of the independent polynomial meet: its own Newton on
    P = P' = P'' = 0 lands within 1e-8 m of it."""
    _, rho0, _, _, w = rpr
    assert w.cusps is not None and len(w.cusps) == 6, w.cusp_how
    assert "3 where the curve only turns" in w.cusp_how
    for x, y in w.cusps:
        rho = (RHO1, x + rho0[1], y + rho0[2])
        roots = _reduced(rho).roots()
        t = min(roots, key=lambda z: np.sort(np.abs(roots - z))[2]).real  # the middle of the tightest three
        r2, r3, _ = rpr3_cusp(RHO1, rho[1], rho[2], t)
        assert abs(r2 - rho[1]) < 1e-8 and abs(r3 - rho[2]) < 1e-8, (rho, r2, r3)


def test_the_five_bars_witnesses_are_on_its_closed_form_and_its_trace_is_complete(tmp_path):
    """The five-bar (one RRR dyad on the two motors): each witness where the distal links are in line, |B1 B2| =
    b1 + b2 or b1 - b2 (the closed form, from the elbows placed here), the edge witnesses exactly where that
    closed form's mode count (2 between, 0 outside) changes along the box's edges, and the trace complete."""
    text, elbows = five_bar(**FIVE_BAR)
    path = tmp_path / "five_bar.urdf"
    path.write_text(text)
    solver = screwkin.PositionSolver(screwkin.load(path))
    b1, b2 = FIVE_BAR["b1"], FIVE_BAR["b2"]
    lo, hi = np.radians(-90.0), np.radians(90.0)
    w = witnesses(solver, "motor1", "motor2", ((lo, hi), (lo, hi)), {})
    assert w.certified and w.cusps == () and len(w.points) == 4

    def apart(m1, m2):
        _, _, B1, B2 = elbows(m1, m2)
        return np.linalg.norm(B2 - B1)
    for p in w.points:
        d = apart(*p.angles)
        assert min(abs(d - (b1 + b2)), abs(d - (b1 - b2))) < 1e-12, (p.system, d)
    s = np.linspace(lo, hi, 1801)
    changes = []
    for axis in (0, 1):
        for bound in (lo, hi):
            count = [2 if b1 - b2 < apart(*((bound, v) if axis == 0 else (v, bound))) < b1 + b2 else 0 for v in s]
            changes += [(axis, bound, 0.5 * (s[k] + s[k + 1])) for k in np.nonzero(np.diff(count))[0]]
    edge = [p for p in w.points if p.system == "edge"]
    assert len(changes) == len(edge) == 2
    for axis, bound, v in changes:
        assert sum(abs(p.xy[axis] - bound) < 1e-12 and abs(p.xy[1 - axis] - v) <= s[1] - s[0] for p in edge) == 1
    traced = trace_loci(solver, "motor1", np.linspace(lo, hi, 19), "motor2", np.linspace(lo, hi, 19), {})
    assert traced.complete and traced.cusps_complete and not traced.cusps and len(traced.loci) == 2


def test_no_certificate_where_the_witnesses_do_not_apply():
    """The Stephenson six-bar has two dyads: no witnesses are built for it, and the trace says why it claims
    nothing."""
    mech = screwkin.load(ROBOTS / "stephenson_sixbar.urdf")
    solver = screwkin.PositionSolver(mech)
    w = witnesses(solver, solver.inputs[0], solver.inputs[-1], ((0.0, 1.0), (0.0, 1.0)), {})
    assert not w.certified and "no certificate" in w.how and not w.points


@pytest.mark.slow
def test_a_certified_trace_leaves_no_change_of_the_independent_count_unexplained(rpr):
    """Another section (rho1 = 0.25 m): the trace is complete, and on a 121 x 121 grid every pair of neighbours
    where the independent polynomial's real-root count differs has a traced curve within a cell and a half."""
    solver, rho0, _, _, _ = rpr
    rho1 = 0.25
    xs, ys = np.linspace(LO, HI, 41) - rho0[1], np.linspace(LO, HI, 41) - rho0[2]
    traced = trace_loci(solver, "leg2", xs, "leg3", ys, {"leg1": rho1 - rho0[0]})
    assert traced.complete and traced.cusps_complete
    g = np.linspace(LO, HI, 121)
    cell = g[1] - g[0]
    counts = np.array([[_real_count((rho1, a, b)) for a in g] for b in g])  # [y, x]
    dense = []
    for lc in traced.loci:
        pts = lc.points + rho0[1:]
        for a, b in zip(pts[:-1], pts[1:]):
            dense.append(a + np.outer(np.linspace(0, 1, int(np.ceil(np.linalg.norm(b - a) / (cell / 4))) + 1), b - a))
    dense = np.vstack(dense)
    changes = 0
    for j in range(len(g)):
        for i in range(len(g)):
            for dj, di in ((0, 1), (1, 0)):
                if j + dj < len(g) and i + di < len(g) and counts[j, i] != counts[j + dj, i + di]:
                    changes += 1
                    mid = np.array([(g[i] + g[i + di]) / 2, (g[j] + g[j + dj]) / 2])
                    assert np.abs(dense - mid).max(axis=1).min() <= 1.5 * cell, mid
    assert changes > 100  # the curves cross the grid's cells

"""The map's grid walked a wavefront at a time with batched steps (issue 44: a 200 x 200 map in seconds) gives
the answers of the walk one point at a time: the same cells reached, from the same neighbours (so on the same
sheet of the same mode), the same seams, and each cell's configuration and log10 sigma_min to round-off.

References outside the batched code: the point-by-point walk (continuation.Neighbour, Pinocchio's closure, one
configuration at a time), the PositionSolver's own solve at every cell (the five-bar's closed form, its two
modes), Pinocchio's closure residual and analysis.singular.measures at each configuration."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from loci_robots import FIVE_BAR, five_bar

import screwkin
from screwkin.analysis.motion.continuation import Neighbour
from screwkin.analysis.singular import Generic, measures
from screwkin.analysis.singularities import maps
from screwkin.analysis.singularities.loci import trace_loci
from screwkin.analysis.singularities.maps import singularity_map

ROBOTS = Path(__file__).resolve().parents[3] / "robots"


def _point_by_point(solver, xn, xs, yn, ys, fixed, q_first, output=None, point=False):
    """The map's breadth-first walk with one continuation step at a time (maps._grow: the walk before the
    batches) and the measures one configuration at a time."""
    mech = solver.mech
    steps = {xn: Neighbour(solver, xn), yn: Neighbour(solver, yn)}
    qs, reached = maps._grow(steps, mech.nq, xn, xs, yn, ys, q_first)
    g = Generic(mech, solver.inputs, output, point, configurations=solver.generic().configurations)
    logs = np.full(reached.shape, np.nan)
    for j, i in zip(*np.nonzero(reached)):
        m = measures(mech, qs[j, i], g)
        logs[j, i] = np.log10(max(min(m.values()), 1e-16))
    seam = maps.seams(mech, qs, reached, steps[xn], steps[yn], xs, ys)
    return qs, reached, logs, seam


def _compare(mech, res, ref):
    qs, reached, logs, seam = ref
    assert np.array_equal(res.reached, reached)
    assert np.array_equal(res.seams, seam)
    J, I = np.nonzero(reached)
    np.testing.assert_allclose(res.q[J, I], qs[J, I], rtol=0, atol=1e-9)
    np.testing.assert_allclose(res.log_sigma[J, I], logs[J, I], rtol=0, atol=1e-9)
    for j, i in zip(J, I):  # every reached configuration closes the loops (Pinocchio's rows)
        assert np.linalg.norm(mech.closure.residual(res.q[j, i])) < 1e-9


def test_the_batched_five_bar_map_is_the_point_by_point_walk_and_the_solvers_mode(wide_five_bar):
    mech = screwkin.load(wide_five_bar)
    solver = screwkin.PositionSolver(mech)
    xs = ys = np.linspace(-np.pi, np.pi, 21)
    q_first = solver.solve({"motor1": xs[0], "motor2": ys[0]}).solutions[0].q
    res = singularity_map(solver, "motor1", xs, "motor2", ys, q_start=q_first)
    assert maps.batch_closure(mech) is not None  # (the batched walk is the one taken)
    assert 0 < res.reached.sum() < res.reached.size  # cells past the fold: the walk's refusals are compared too
    _compare(mech, res, _point_by_point(solver, "motor1", xs, "motor2", ys, {}, q_first))
    # each reached cell is one of the modes the solver finds there on its own (closed form), and its value is
    # that mode's measure
    g = Generic(mech, solver.inputs, configurations=solver.generic().configurations)
    for j, i in zip(*np.nonzero(res.reached)):
        modes = [s.q for s in solver.solve({"motor1": xs[i], "motor2": ys[j]}).solutions]
        gap = [np.abs(mech.difference(q, res.q[j, i])).max() for q in modes]
        k = int(np.argmin(gap))
        assert gap[k] < 1e-7, (j, i, gap)
        m = measures(mech, modes[k], g)
        assert abs(np.log10(max(min(m.values()), 1e-16)) - res.log_sigma[j, i]) < 1e-6


@pytest.mark.parametrize("point", [True, False])
def test_the_batched_map_with_an_output_measures_its_serial_singularities_as_one_at_a_time(point):
    """With --output the stacked measures take the output link's Jacobian from the batched tree (serial kind)."""
    mech = screwkin.load(ROBOTS / "five_bar.urdf")
    solver = screwkin.PositionSolver(mech)
    xs, ys = np.linspace(-1.2, 1.4, 9), np.linspace(-1.0, 1.3, 8)
    q_first = solver.solve({"motor1": xs[0], "motor2": ys[0]}).solutions[0].q
    res = singularity_map(solver, "motor1", xs, "motor2", ys, {}, "tip", point, q_start=q_first)
    assert "serial" in set(res.kind[res.reached])
    _compare(mech, res, _point_by_point(solver, "motor1", xs, "motor2", ys, {}, q_first, "tip", point))


@pytest.mark.slow
def test_the_batched_3rpr_map_is_the_point_by_point_walk():
    mech = screwkin.load(ROBOTS / "planar_3rpr.urdf")
    solver = screwkin.PositionSolver(mech, list(mech.actuated))
    xs = ys = np.linspace(0.15, -0.08, 15)  # past a fold: a third of the box is not reached
    fixed = {"leg1": 0.0}
    q_first = solver.solve({"leg2": xs[0], "leg3": ys[0], **fixed}).solutions[0].q
    res = singularity_map(solver, "leg2", xs, "leg3", ys, fixed, q_start=q_first)
    assert 0 < res.reached.sum() < res.reached.size
    _compare(mech, res, _point_by_point(solver, "leg2", xs, "leg3", ys, fixed, q_first))
    values = mech.joint_values
    for j, i in zip(*np.nonzero(res.reached)):  # the inputs at the cell's values
        v = values(res.q[j, i])
        assert abs(v["leg2"] - xs[i]) < 1e-12 and abs(v["leg3"] - ys[j]) < 1e-12 and abs(v["leg1"]) < 1e-12


def test_a_small_oval_inside_one_grid_cell_is_proved_found_and_serial_loci_are_not_claimed(tmp_path):
    """map --loci seeds its curves from a coarse grid (analysis.singularities.loci): a component between the grid's
    nodes may be missed.  Here the one component in the box is a small oval (the distal links folded onto each
    other, |B1 B2| = b1 - b2, a few degrees across) inside one cell of the 9 x 9 seed grid; it is found, and the
    witnesses prove nothing else is there (loci_witness: one RRR dyad on two motors) -- its two points where
    motor1 is largest or least among them.  With the serial loci too (--output) completeness is not claimed:
    the certificate covers the actuator loci only."""
    dims = dict(FIVE_BAR, b2=0.145)
    text, elbows = five_bar(**dims)
    path = tmp_path / "five_bar_oval.urdf"
    path.write_text(text)
    mech = screwkin.load(path)
    solver = screwkin.PositionSolver(mech)
    xs, ys = np.radians(np.linspace(-100, -10, 9)), np.radians(np.linspace(20, 110, 9))
    traced = trace_loci(solver, "motor1", xs, "motor2", ys, {})
    assert traced.complete is True and traced.cusps_complete is True
    assert "Complete: witnesses" in traced.how and "with G_y = 0, 2; with an input at a bound of the box, 0" in traced.how
    both = trace_loci(solver, "motor1", xs, "motor2", ys, {}, output="tip", kinds=("actuator", "serial"))
    assert both.complete is False and "completeness is not claimed" in both.how
    assert "it covers the actuator loci only" in both.how
    # the oval: |B1 B2| = b1 - b2 at every point, closed, strictly inside one grid cell (no node inside it)
    (oval,) = [lc for lc in traced.loci if lc.kind == "actuator"]
    assert oval.closed
    for m1, m2 in oval.points:
        _, _, B1, B2 = elbows(m1, m2)
        assert abs(np.linalg.norm(B2 - B1) - (dims["b1"] - dims["b2"])) < 1e-9 * (dims["b1"] + dims["b2"])
    lo, hi = oval.points.min(axis=0), oval.points.max(axis=0)
    assert not any(lo[0] <= x <= hi[0] for x in xs) and not any(lo[1] <= y <= hi[1] for y in ys)

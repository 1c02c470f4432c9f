"""The compiled inner loop (screwkin.model.kernel.compiled, numba) gives the numpy loop's numbers: the same
model.kernel.newton.iterate with the rows, the step and the verdict compiled."""

import dataclasses

import numpy as np
import pinocchio as pin
import pytest
from conftest import CORPUS, ROBOTS, fourbar

import screwkin
from screwkin.analysis.position.position import PositionSolver
from screwkin.model.kernel import compiled, newton

pytest.importorskip("numba")


@pytest.mark.parametrize("name", ["cassie_like", "digit_like", "robot_delta"])
def test_rows_equal_the_numpy_rows(name):
    """Welds (6d) and ball joints (3d) of the corpus, at random configurations far from
    closure: residual and Jacobian rows as ClosureSystem.evaluate(q, solver=True)."""
    mech = screwkin.load(CORPUS / name / "robot.urdf", warn=lambda m: None)
    closure = mech.closure
    assert closure.accelerate()
    rng = np.random.default_rng(0)
    for _ in range(5):
        q = pin.integrate(mech.model, pin.neutral(mech.model), rng.normal(size=mech.nv))
        r, K = compiled.cut_rows(closure, q)
        r0, K0 = closure.evaluate(q, solver=True)
        np.testing.assert_allclose(r, r0, rtol=0, atol=1e-15)
        np.testing.assert_allclose(K, K0, rtol=0, atol=1e-14)
        r1, none = compiled.cut_rows(closure, q, jacobian=False)
        assert none is None
        np.testing.assert_allclose(r1, r0, rtol=0, atol=1e-15)


def test_track_gives_the_numpy_configurations():
    plain = screwkin.load(CORPUS / "cassie_like" / "robot.urdf", warn=lambda m: None)
    fast = screwkin.load(CORPUS / "cassie_like" / "robot.urdf", warn=lambda m: None)
    a, b = PositionSolver(plain), PositionSolver(fast, compiled=True)
    assert b.compiled and not a.compiled
    q0 = plain.assemble().q
    motors = {n: v for n, v in a.joint_values(q0).items() if n in plain.actuated}
    for k, delta in enumerate((0.02, -0.05, 0.08)):
        target = dict(motors)
        name = plain.actuated[k % len(plain.actuated)]
        target[name] += delta
        x, y = a.track(target, q0), b.track(target, q0)
        assert x.iterations == y.iterations and y.residual < 1e-10
        np.testing.assert_allclose(y.q, x.q, rtol=0, atol=1e-12)
        assert np.linalg.norm(fast.closure.residual(y.q)) < 1e-10  # checked with the numpy rows


def test_other_cut_types_stay_with_numpy(tmp_path):
    path = tmp_path / "fb.urdf"
    path.write_text(fourbar())
    mech = screwkin.load(path)
    assert not mech.closure.accelerate()  # a revolute cut joint: no kernel for it
    solver = PositionSolver(mech, ["crank_joint"], compiled=True)
    assert not solver.compiled
    assert len(solver.solve({"crank_joint": 0.3}).solutions) == 2
    stewart = screwkin.load(ROBOTS / "gough_stewart_6ups.urdf")
    assert PositionSolver(stewart, compiled=True).compiled == all(c.type in ("spherical", "fixed")
                                                                  for c in stewart.cuts)


ACCELERATED = ["5bar_linkage", "5bar_linkage_iso3d", "cassie_like", "digit_like", "robot_delta", "talos_like"]


@pytest.mark.parametrize("name", ACCELERATED)
def test_the_compiled_loop_takes_the_numpy_loops_steps(name):
    """Corpus robots the kernels know, from starts moved off an assembled configuration (motors held):
    the compiled solve takes the numpy solve's steps -- the same accepted and refused steps, the same
    iterations -- and both close the loops.  Their configurations and residuals along the way agree
    to round-off amplified by the damped minimum-norm step (K of these robots has singular values
    down to about 1e-9 of its largest: idle and nearly idle motions): configurations to at most
    1.4e-6 rad on robot_delta and digit_like, residuals to 1e-6 of the first, as before the loop
    was one (the compiled and numpy paths of 6483d8a differ as much)."""
    plain = screwkin.load(CORPUS / name / "robot.urdf", warn=lambda m: None)
    fast = screwkin.load(CORPUS / name / "robot.urdf", warn=lambda m: None)
    assert fast.closure.accelerate() and not plain.closure.accelerated
    q0 = plain.assemble().q
    frozen = plain.velocity_indices(plain.actuated)
    rng = np.random.default_rng(11)
    for _ in range(4):
        start = pin.integrate(plain.model, q0, 0.05 * rng.normal(size=plain.nv))
        x, y = [], []
        a = plain.closure.solve(start, frozen=frozen, trace=lambda *step: x.append(step))
        b = fast.closure.solve(start, frozen=frozen, trace=lambda *step: y.append(step))
        assert a.iterations == b.iterations == len(x) == len(y) > 0
        assert [s[5] for s in x] == [s[5] for s in y]
        scale = np.linalg.norm(x[0][2])
        for (_, qa, ra, *_), (_, qb, rb, *_) in zip(x, y):
            assert abs(np.linalg.norm(rb) - np.linalg.norm(ra)) <= 1e-6 * scale
            np.testing.assert_allclose(qb, qa, rtol=0, atol=1e-5)
        np.testing.assert_allclose(b.q, a.q, rtol=0, atol=1e-5)
        assert max(a.residual, b.residual) < plain.tolerances.closure
        assert np.linalg.norm(plain.closure.residual(b.q)) < plain.tolerances.closure  # checked with numpy's rows


def test_the_compiled_step_falls_back_where_numbas_solve_raises():
    """numba's np.linalg.solve raises np.linalg.LinAlgError -- nothing else in the kernel raises --
    for a singular damped system (K = 0 with no damping: A = 0) and for an inf or a NaN; the
    compiled step then gives the numpy step: the least-squares solution (zero here, as
    np.linalg.lstsq gives) and NaN for a NaN (as numpy's solve gives)."""
    kernel = compiled.kernels().damped_step
    free = np.arange(4, dtype=np.int64)
    K, r = np.zeros((3, 4)), np.array([1.0, -2.0, 0.5])
    with pytest.raises(np.linalg.LinAlgError, match="singular"):
        kernel(K, r, free, 0.0)
    dq, lin = compiled.damped_step(K, r, free, 0.0)
    np.testing.assert_array_equal(dq, 0.0)  # lstsq of the zero system: the minimum-norm solution
    assert lin == pytest.approx(r @ r, rel=1e-15)
    bad = np.ones((3, 4))
    bad[1, 2] = np.nan
    with pytest.raises(np.linalg.LinAlgError, match="infs or NaNs"):
        kernel(bad, r, free, 1e-3)
    dq, lin = compiled.damped_step(bad, r, free, 1e-3)
    ref, ref_lin = newton.damped_step(bad, r, free, 1e-3)
    assert np.isnan(dq).all() and np.isnan(ref).all() and np.isnan(lin) and np.isnan(ref_lin)
    rng = np.random.default_rng(2)  # and where it does not raise, the kernel's own numbers
    K, r = rng.normal(size=(6, 4)), rng.normal(size=6)
    np.testing.assert_allclose(compiled.damped_step(K, r, free, 1e-3)[0], kernel(K, r, free, 1e-3)[0], rtol=0, atol=0)


def test_a_singular_step_in_the_compiled_solve_is_the_numpy_solves(monkeypatch):
    """A solve whose damped systems are singular: talos_like with every joint of its loop held, so
    the one free column (a joint outside the loop) of K is exactly zero, and no damping (lm_damping
    and its floor 0): A = 0.  numba's solve raises, the compiled step takes the numpy step's least
    squares (counted), the step is zero and refused until the iteration limit: the compiled solve
    does what the numpy solve does."""
    plain = screwkin.load(CORPUS / "talos_like" / "robot.urdf", warn=lambda m: None)
    fast = screwkin.load(CORPUS / "talos_like" / "robot.urdf", warn=lambda m: None)
    fast.closure.accelerate()
    undamped = dataclasses.replace(plain.tolerances, lm_damping=0.0, lm_damping_min=0.0, max_iterations=5)
    q0 = plain.assemble().q
    K = plain.closure.evaluate(q0, True, solver=True)[1]
    outside = np.flatnonzero(~K.any(axis=0))
    assert outside.tolist() == [8]
    frozen = np.setdiff1d(np.arange(plain.nv), outside)
    start = pin.integrate(plain.model, q0, 0.05 * np.random.default_rng(1).normal(size=plain.nv))
    fallbacks = []
    numpy_step = newton.damped_step
    monkeypatch.setattr(newton, "damped_step", lambda *a: fallbacks.append(1) or numpy_step(*a))
    traces = []
    for mech in (plain, fast):
        steps = []
        with pytest.raises(screwkin.errors.AssemblyError) as info:
            mech.closure.solve(start, frozen=frozen, tolerances=undamped, trace=lambda *step: steps.append(step))
        assert info.value.iterations == 5
        traces.append(steps)
    assert len(fallbacks) == 5  # the compiled solve's five steps, each through the fallback
    for (_, qa, ra, _, dqa, oka), (_, qb, rb, _, dqb, okb) in zip(*traces):
        assert not oka and not okb and not dqa.any() and not dqb.any()
        np.testing.assert_array_equal(qa, qb)
        np.testing.assert_allclose(rb, ra, rtol=0, atol=1e-15)

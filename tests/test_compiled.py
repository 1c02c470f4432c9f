"""The compiled inner loop (screwkin.model.compiled, numba) gives the numpy loop's numbers."""

import numpy as np
import pinocchio as pin
import pytest
from conftest import CORPUS, ROBOTS, fourbar

import screwkin
from screwkin.analysis.motion.position import PositionSolver

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
        r, K = closure._evaluate_compiled(q)
        r0, K0 = closure.evaluate(q, solver=True)
        np.testing.assert_allclose(r, r0, rtol=0, atol=1e-15)
        np.testing.assert_allclose(K, K0, rtol=0, atol=1e-14)
        r1, none = closure._evaluate_compiled(q, jacobian=False)
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

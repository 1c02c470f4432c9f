"""The one damped-Newton loop (model.kernel.newton.iterate) for one configuration and for stacks: each
configuration of a stack iterates as it would alone (its own damping, acceptance and end), on the
configuration manifold (continuous joints' (cos, sin), quaternions), the trace and the residual-only
last evaluation of the single solve, and the give-up rule counted by hand."""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest
from conftest import DATA

import screwkin
from screwkin.errors import AssemblyError
from screwkin.model.kernel import newton
from screwkin.model.manifold import Integrator
from screwkin.tolerances import DEFAULT


@pytest.fixture(scope="module")
def delta_rss():
    """A 3-RSS delta from MJCF: ball joints at the elbows and a free-flying platform closed by three
    <connect>s, so quaternions in the configuration (nq = 22, nv = 18); the motors held."""
    mech = screwkin.load(DATA / "mjcf" / "delta_rss.xml", warn=lambda m: None)
    assert (mech.model.nq, mech.model.nv) == (22, 18)
    return mech


def quaternions(mech, q):
    """The unit quaternions in q (ball joints and the free flyer)."""
    out = []
    for j in range(1, mech.model.njoints):
        short, i = mech.model.joints[j].shortname(), mech.model.idx_qs[j]
        if short == "JointModelSpherical":
            out.append(q[i:i + 4])
        elif short == "JointModelFreeFlyer":
            out.append(q[i + 3:i + 7])
    return out


def starts_near(mech, count, size, seed):
    q0 = mech.assemble().q
    rng = np.random.default_rng(seed)
    return np.array([pin.integrate(mech.model, q0, size * rng.normal(size=mech.nv)) for _ in range(count)])


def stacked(system):
    """ClosureSystem's solver rows for a stack, one configuration at a time."""

    def evaluate(Q, which, jacobian):
        rows = [system.evaluate(q, jacobian, solver=True) for q in Q]
        return np.array([r for r, _ in rows]), (np.array([K for _, K in rows]) if jacobian else None)

    return evaluate


def test_a_stack_iterates_each_configuration_as_it_would_alone(delta_rss):
    """The stack (numpy's stacked step, the numpy SO(3) and SE(3) integration) against
    ClosureSystem.solve on each start alone (the step of one configuration, pin.integrate): the same
    iterations, the same configurations to round-off, on the manifold.  The motors are held."""
    mech = delta_rss
    system = mech.closure
    frozen = mech.velocity_indices(mech.actuated)
    S = starts_near(mech, 6, 0.1, 1)
    S[3] = S[0]  # the same start twice: each has its own damping and end
    out = newton.iterate(stacked(system), S, system.free_columns(frozen), DEFAULT, Integrator(mech.model))
    assert out.converged.all()
    for s, q, its, res in zip(S, out.q, out.iterations, out.residual):
        alone = system.solve(s, frozen=frozen)
        assert its == alone.iterations and res < DEFAULT.closure
        np.testing.assert_allclose(q, alone.q, rtol=0, atol=1e-12)
        for quat in quaternions(mech, q):
            assert quat @ quat == pytest.approx(1.0, abs=1e-12)
        for name in mech.actuated:  # held
            i = mech.coordinate(name).idx_q
            assert q[i] == s[i]


def test_quaternions_of_a_stack_stay_on_the_manifold():
    """A free flyer, a ball joint and a revolute joint carry a frame to a target pose: residual
    log6(M_target^-1 M(q)), Jacobian Jlog6 J (LOCAL frame Jacobian).  The stack (the numpy SE(3) and
    SO(3) integration) against each start alone (N = 1: pin.integrate); both reach the pose."""
    model = pin.Model()
    free = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "free")
    ball = model.addJoint(free, pin.JointModelSpherical(), pin.SE3(np.eye(3), np.array([0.3, 0.0, 0.0])), "ball")
    hinge = model.addJoint(ball, pin.JointModelRZ(), pin.SE3(np.eye(3), np.array([0.0, 0.2, 0.0])), "hinge")
    frame = model.addFrame(pin.Frame("tip", hinge, 0, pin.SE3(np.eye(3), np.array([0.1, 0.0, 0.0])),
                                     pin.FrameType.OP_FRAME))
    data = model.createData()
    rng = np.random.default_rng(4)
    q_star = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
    pin.framesForwardKinematics(model, data, q_star)
    target = data.oMf[frame].copy()

    def evaluate(Q, which, jacobian):
        r, K = np.empty((len(Q), 6)), np.empty((len(Q), 6, model.nv))
        for n, q in enumerate(Q):
            pin.computeJointJacobians(model, data, q)
            pin.updateFramePlacements(model, data)
            error = target.actInv(data.oMf[frame])
            r[n] = pin.log6(error).vector
            K[n] = pin.Jlog6(error) @ pin.getFrameJacobian(model, data, frame, pin.ReferenceFrame.LOCAL)
        return r, (K if jacobian else None)

    S = np.array([pin.integrate(model, q_star, 0.4 * rng.normal(size=model.nv)) for _ in range(5)])
    free_columns = np.arange(model.nv)
    out = newton.iterate(evaluate, S, free_columns, DEFAULT, Integrator(model))
    assert out.converged.all()
    for s, q, its in zip(S, out.q, out.iterations):
        alone = newton.iterate(evaluate, s[None], free_columns, DEFAULT, Integrator(model), newton.one_step)
        assert alone.converged[0] and alone.iterations[0] == its
        np.testing.assert_allclose(q, alone.q[0], rtol=0, atol=1e-12)
        for quat in (q[3:7], q[7:11]):
            assert quat @ quat == pytest.approx(1.0, abs=1e-12)
        pin.framesForwardKinematics(model, data, q)
        np.testing.assert_allclose(pin.log6(target.actInv(data.oMf[frame])).vector, 0.0, atol=DEFAULT.closure)


def test_a_configuration_gives_up_when_refused_steps_push_its_damping_past_the_limit():
    """Two independent problems in one stack: x^2 + x - 2 = 0 from x = 3 (Newton converges), and a
    constant residual with a zero Jacobian (every step refused: the residual never goes down).  The
    second gives up after k refusals, the first k with lm_damping 2^1 2^2 ... 2^k > lm_damping_max
    (the damping times nu, nu doubling from 2): 2^(k(k+1)/2) > 1e10 / 1e-9, k = 11.  The first
    converges as it does alone."""
    tol = DEFAULT
    k = next(k for k in range(1, 40) if tol.lm_damping * 2.0 ** (k * (k + 1) / 2) > tol.lm_damping_max)
    assert k == 11

    def evaluate(Q, which, jacobian):
        x = Q[:, 0]
        r = np.where(which == 0, x * x + x - 2.0, 1.0)[:, None]
        K = np.where(which == 0, 2 * x + 1.0, 0.0)[:, None, None]
        return r, (K if jacobian else None)

    def add(Q, dQ):
        return Q + dQ

    out = newton.iterate(evaluate, np.array([[3.0], [3.0]]), np.arange(1), tol, add)
    assert out.converged.tolist() == [True, False]
    assert out.iterations[1] == k and out.residual[1] == 1.0 and out.q[1, 0] == 3.0
    assert abs(out.q[0, 0] - 1.0) < tol.closure  # the root x = 1
    alone = newton.iterate(evaluate, np.array([[3.0]]), np.arange(1), tol, add)
    assert alone.iterations[0] == out.iterations[0] and alone.q[0, 0] == out.q[0, 0]


def test_the_single_solve_traces_each_step_and_ends_on_the_residual_alone(delta_rss):
    """ClosureSystem.solve(trace=...): one call per step with the configuration it started from,
    its solver rows and Jacobian, the step (the held motors' columns zero) and whether it was
    accepted; an accepted step's configuration is pin.integrate(q, dq), where the next one starts.
    A step taken from a residual below 0.1 sqrt(closure) (quadratic convergence in sight) has its
    residual computed without the Jacobian, which is computed after all when it neither converged
    nor was refused."""
    mech = delta_rss
    system = mech.closure
    frozen = mech.velocity_indices(mech.actuated)
    near = 0.1 * np.sqrt(DEFAULT.closure)
    evaluate = system.evaluate
    residual_alone = 0
    for start in starts_near(mech, 4, 0.1, 2):
        steps, asked = [], []
        system.evaluate = lambda q, jacobian=True, solver=False: asked.append(jacobian) or evaluate(q, jacobian, solver)
        try:
            a = system.solve(start, frozen=frozen, trace=lambda *step: steps.append(step))
        finally:
            del system.evaluate
        assert [s[0] for s in steps] == list(range(1, a.iterations + 1))
        np.testing.assert_array_equal(steps[0][1], start)
        expected = [True]
        for (_, q, r, K, dq, ok), following in zip(steps, steps[1:] + [None]):
            r_ref, K_ref = evaluate(q, True, solver=True)
            np.testing.assert_array_equal(r, r_ref)
            np.testing.assert_array_equal(K, K_ref)
            assert not dq[frozen].any()
            moved = pin.integrate(mech.model, q, dq)
            if ok:
                np.testing.assert_array_equal(moved, following[1] if following else a.q)
            final = np.linalg.norm(r) < near
            expected.append(not final)
            if final and ok and np.linalg.norm(evaluate(moved, False, solver=True)[0]) >= DEFAULT.closure:
                expected.append(True)
        assert asked == expected
        residual_alone += expected.count(False)
    assert residual_alone  # the shortcut was taken


def test_the_single_solve_reports_the_residual_it_reached(delta_rss):
    """Too few iterations: AssemblyError with the residual norm of the last accepted configuration."""
    mech = delta_rss
    start = starts_near(mech, 1, 0.1, 3)[0]
    few = dataclasses.replace(DEFAULT, max_iterations=1)
    steps = []
    with pytest.raises(AssemblyError) as info:
        mech.closure.solve(start, frozen=mech.velocity_indices(mech.actuated), tolerances=few,
                           trace=lambda *step: steps.append(step))
    assert len(steps) == 1 and steps[0][5]  # one step, accepted
    _, q, r, K, dq, _ = steps[0]
    reached = mech.closure.evaluate(pin.integrate(mech.model, q, dq), False, solver=True)[0]
    assert info.value.residual == pytest.approx(float(np.linalg.norm(reached)), rel=1e-12)

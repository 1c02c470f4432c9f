"""The one damped-Newton step and verdict (model/kernel/newton.py) of the single, batched and compiled
solvers: the three give the same step as the damped normal equations written here, the verdict
(numpy and compiled) follows Nielsen's rule as published, and the batched closure rows equal
ClosureSystem's (the program no longer compares them at run time: this test does).  The loop
itself, below: the one damped-Newton loop (model.kernel.newton.iterate) for one configuration and for stacks: each
configuration of a stack iterates as it would alone (its own damping, acceptance and end), on the
configuration manifold (continuous joints' (cos, sin), quaternions), the trace and the residual-only
last evaluation of the single solve, and the give-up rule counted by hand."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from conftest import DATA

import screwkin
from screwkin.model.kernel.stacks import BatchClosure, Unbatchable
from screwkin.errors import AssemblyError
from screwkin.model.kernel import compiled, newton
from screwkin.model.manifold import Integrator
from screwkin.tolerances import DEFAULT

ROBOTS = Path(__file__).resolve().parents[3] / "robots"


def reference_step(Kf, r, mu):
    """The damped step from its definition: minimise |r + Kf d|^2 + lam |d|^2 with
    lam = mu * trace(Kf Kf^T) / rows, i.e. (Kf^T Kf + lam I) d = -Kf^T r."""
    lam = mu * max(np.trace(Kf @ Kf.T) / Kf.shape[0], 1e-12)
    n = Kf.shape[1]  # as the least-squares problem [Kf; sqrt(lam) I] d = [-r; 0] (no normal equations)
    d = np.linalg.lstsq(np.vstack([Kf, np.sqrt(lam) * np.eye(n)]), np.concatenate([-r, np.zeros(n)]), rcond=None)[0]
    lin = r + Kf @ d
    return d, lin @ lin


@pytest.mark.parametrize("rows, cols", [(3, 7), (6, 6), (12, 5), (1, 4)])
@pytest.mark.parametrize("mu", [1e-9, 1e-3, 10.0])
def test_single_batched_and_compiled_steps_are_the_damped_least_squares_step(rows, cols, mu):
    rng = np.random.default_rng(rows * 100 + cols)
    K = rng.normal(size=(rows, cols + 2))
    r = rng.normal(size=rows)
    free = np.arange(2, cols + 2)
    Kf = K[:, free]
    d_ref, lin_ref = reference_step(Kf, r, mu)
    d1, lin1 = newton.damped_step(K, r, free, mu)
    scale = max(1.0, np.abs(d_ref).max())
    np.testing.assert_allclose(d1, d_ref, rtol=0, atol=1e-8 * scale)
    assert abs(lin1 - lin_ref) <= 1e-8 * max(1.0, r @ r)
    D, L = newton.damped_steps(np.repeat(Kf[None], 3, 0), np.repeat(r[None], 3, 0), np.full(3, mu))
    for k in range(3):
        np.testing.assert_allclose(D[k], d1, rtol=0, atol=1e-12 * scale)
        assert abs(L[k] - lin1) <= 1e-12 * max(1.0, r @ r)
    if compiled.available():
        dc, linc = compiled.kernels().damped_step(np.ascontiguousarray(K), r, free.astype(np.int64), mu)
        np.testing.assert_allclose(dc, d1, rtol=0, atol=1e-10 * scale)
        assert abs(linc - lin1) <= 1e-10 * max(1.0, r @ r)


def test_rank_deficient_rows_still_give_a_finite_step():
    K = np.array([[1.0, 2.0, 0.0], [2.0, 4.0, 0.0]])  # rank 1
    r = np.array([1.0, 2.0])
    d, lin = newton.damped_step(K, r, np.arange(3), 1e-9)
    assert np.all(np.isfinite(d))
    # the minimum-norm solution of the consistent system K d = -r: d = -K^+ r
    np.testing.assert_allclose(d, -np.linalg.pinv(K) @ r, rtol=0, atol=1e-6)


def nielsen(norm, new_norm, lin2, mu, nu, tol):
    """Nielsen's rule as written in Madsen, Nielsen and Tingleff, "Methods for non-linear least squares
    problems" (2004), eq. 2.21, with the gain ratio rho = (F(x) - F(x_new)) / (L(0) - L(h)) of its
    eq. 2.18, F the squared residual and L the linear model's: an accepted step (the residual went
    down) takes mu max(1/3, 1 - (2 rho - 1)^3) and nu = 2, a refused one mu nu and 2 nu; never below
    lm_damping_min; a refused step past lm_damping_max gives up."""
    predicted = norm**2 - lin2
    rho = (norm**2 - new_norm**2) / predicted if predicted > 0 else 0.0
    if new_norm < norm:
        mu, nu = max(mu * max(1 / 3, 1 - (2 * rho - 1) ** 3), tol.lm_damping_min), 2.0
        return True, mu, nu, new_norm >= tol.closure
    mu, nu = mu * nu, 2 * nu
    return False, mu, nu, norm >= tol.closure and mu <= tol.lm_damping_max


def _verdict(kind):
    """The loop's verdict: numpy's, or numba's compiled form (a skip naming numba where it is missing:
    under CI=true that skip fails the run)."""
    if kind == "numpy":
        return newton.judge
    pytest.importorskip("numba")
    return compiled.kernels().judge


@pytest.mark.parametrize("kind", ["numpy", "compiled"])
def test_the_verdict_follows_nielsens_rule(kind):
    """Every case of the rule in one stack (and the stack's entries one at a time): accepted with rho
    between 0 and 1, above 1, with no predicted decrease, converged; refused, refused past the
    damping limit; the floor on the damping."""
    verdict = _verdict(kind)
    tol = DEFAULT
    cases = [  # norm, new norm, |r + K dq|^2, mu, nu
        (2.0, 1.0, 0.0, 1e-3, 2.0), (2.0, 1.0, 3.5, 1e-3, 4.0), (1.0, 0.5, 1.0, 1e-3, 2.0),
        (1.0, 0.9, 0.99, 1e-3, 8.0), (1.0, 0.5, 0.9, tol.lm_damping_min, 2.0), (1e-3, 1e-12, 1e-7, 1e-6, 2.0),
        (1.0, 1.5, 0.2, 1e-3, 2.0), (1.0, 1.0, 0.2, 1e-3, 16.0), (1.0, 2.0, 0.2, 0.6 * tol.lm_damping_max, 2.0),
        (1.0, np.nan, 0.2, 1e-3, 2.0)]
    norm, new, lin2, mu, nu = (np.array(c, float) for c in zip(*cases))
    for sub in (slice(None), *[slice(k, k + 1) for k in range(len(cases))]):
        residual_after = np.zeros((len(new[sub]), 3))
        residual_after[:, 1] = new[sub]  # rows whose norm is the new norm
        ok, after, mu_n, nu_n, going = verdict(norm[sub], residual_after, lin2[sub], mu[sub], nu[sub], tol.closure,
                                               tol.lm_damping_min, tol.lm_damping_max)
        finite = np.isfinite(new[sub])
        np.testing.assert_array_equal(after[finite], new[sub][finite])
        for k, c in enumerate(cases[sub]):
            want = nielsen(*c, tol)
            assert (bool(ok[k]), bool(going[k])) == (want[0], want[3]), (kind, c)
            assert mu_n[k] == pytest.approx(want[1], rel=1e-15) and nu_n[k] == want[2], (kind, c)


BATCHABLE = ["five_bar.urdf", "fourbar_crank_rocker.urdf", "slider_crank_offset.urdf", "watt_sixbar.urdf",
             "delta_parallelogram.urdf", "gough_stewart_6ups.urdf", "planar_3rrr.urdf", "bennett.urdf"]


@pytest.mark.parametrize("name", BATCHABLE)
def test_batched_rows_equal_the_closure_systems(name):
    """BatchClosure's solver rows and constraint Jacobian against ClosureSystem's, at random
    configurations and at closed ones."""
    mech = screwkin.load(ROBOTS / name)
    try:
        bc = BatchClosure(mech)
    except Unbatchable as e:  # pragma: no cover - the list above names batchable robots
        pytest.fail(str(e))
    rng = np.random.default_rng(1)
    Q = np.array([pin.randomConfiguration(mech.model, -np.pi * np.ones(mech.nq), np.pi * np.ones(mech.nq))
                  for _ in range(5)])
    r, K = bc.evaluate(Q)
    for q, rq, Kq in zip(Q, r, K):
        r_ref, K_ref = mech.closure.evaluate(q, True, solver=True)
        np.testing.assert_allclose(rq, r_ref, rtol=0, atol=1e-10)
        np.testing.assert_allclose(Kq, K_ref, rtol=0, atol=1e-10)
    closed = np.array(mech.generic_configurations()[1])
    for q, Kc in zip(closed, bc.constraint_jacobians(closed)):
        np.testing.assert_allclose(Kc, mech.closure.jacobian(q), rtol=0, atol=1e-10)
    del rng


@pytest.mark.parametrize("name", BATCHABLE + ["gear_train_idler.urdf", "tsai_3upu.urdf"])
def test_batched_bias_is_the_second_derivative_of_the_rows(name):
    """BatchClosure.bias (a sweep's K'(q, v) v, all its configurations at once) against a central finite
    difference of the closure rows along q(t) = integrate(q, v t) at closed configurations,
    (r(q + v h) - 2 r(q) + r(q - v h)) / h^2, and against ClosureSystem.bias (Pinocchio's, one at a time)."""
    mech = screwkin.load(ROBOTS / name)
    bc = BatchClosure(mech)
    closed = np.array(mech.generic_configurations()[1])
    V = np.random.default_rng(7).normal(size=(len(closed), mech.nv))
    B = bc.bias(closed, V)
    h = 1e-4
    for q, v, b in zip(closed, V, B):
        rows = [mech.closure.evaluate(pin.integrate(mech.model, q, s * h * v), False)[0] for s in (1, 0, -1)]
        np.testing.assert_allclose(b, (rows[0] - 2 * rows[1] + rows[2]) / h**2, rtol=0, atol=2e-5 * max(1, abs(b).max()))
        np.testing.assert_allclose(b, mech.closure.bias(q, v), rtol=0, atol=1e-10)


@pytest.mark.parametrize("name", ["five_bar.urdf", "gough_stewart_6ups.urdf"])
def test_batched_solver_reaches_the_single_solvers_configurations(name):
    """From the same perturbed starts, both solvers take the same steps and land on the same
    closed configuration (their iterations may differ by the last accepted step)."""
    mech = screwkin.load(ROBOTS / name)
    solver = screwkin.PositionSolver(mech)
    q0 = mech.generic_configurations()[1][0]
    rng = np.random.default_rng(2)
    starts = np.array([pin.integrate(mech.model, q0, 0.05 * rng.normal(size=mech.nv)) for _ in range(4)])
    Qb, conv, norms, _ = BatchClosure(mech).solve(starts, frozen=solver.frozen)
    for qs, qb, ok in zip(starts, Qb, conv):
        a = mech.closure.solve(qs, frozen=solver.frozen)
        assert ok and a.residual < DEFAULT.closure
        np.testing.assert_allclose(pin.difference(mech.model, a.q, qb), 0.0, atol=1e-8)


# ---------------------------------------------------------------- folded in from test_newton_loop.py
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

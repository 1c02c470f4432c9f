"""The one damped-Newton step (model/newton.py) of the single, batched and compiled solvers:
the three give the same step as the damped normal equations written here, the damping follows
Nielsen's rule, and the batched closure rows equal ClosureSystem's (the program no longer
compares them at run time: this test does)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from screwkin.analysis.singularities.batch import BatchClosure, Unbatchable
from screwkin.model import compiled, newton
from screwkin.tolerances import DEFAULT

ROBOTS = Path(__file__).resolve().parents[1] / "robots"


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


def test_damping_follows_nielsens_rule():
    tol = DEFAULT
    for rho in (0.0, 0.25, 0.5, 0.9, 1.0):
        mu, nu = newton.accept(1e-3, rho, tol)
        assert mu == pytest.approx(1e-3 * max(1 / 3, 1 - (2 * rho - 1) ** 3), rel=1e-15)
        assert nu == 2.0
    assert newton.accept(tol.lm_damping_min, 1.0, tol)[0] == tol.lm_damping_min  # never below the floor
    assert newton.refuse(1e-3, 4.0) == (4e-3, 8.0)
    assert newton.given_up(tol.lm_damping_max * 2, tol) and not newton.given_up(1.0, tol)
    # the gain ratio: actual over predicted decrease of the squared residual
    assert newton.gain_ratio(2.0, 1.0, 0.0) == pytest.approx(3.0 / 4.0)
    assert newton.gain_ratio(1.0, 0.5, 1.0) == 0.0  # no decrease predicted
    np.testing.assert_allclose(newton.gain_ratio(np.array([2.0, 1.0]), np.array([1.0, 0.5]), np.array([0.0, 1.0])),
                               [0.75, 0.0])


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

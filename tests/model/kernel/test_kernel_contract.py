"""Every backend of the closure rows keeps the one contract (model/kernel/contract.py, issue 42): each is a
ClosureKernel, and on several bundled mechanisms its rows, their Jacobian, its step on the configuration
manifold, its constraint Jacobian and acceleration term are Pinocchio's -- the rows and Jacobian to 1e-12 of
the Pinocchio backend's, the Jacobian also to central finite differences of its own rows (outside the code
under test), the step to pin.integrate.  The polynomial rows are other equations with the same real zeros:
they vanish where Pinocchio closes the loops and not at configurations where Pinocchio's rows do not."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from screwkin.analysis.position.position import PositionSolver
from screwkin.model.kernel.algebraic import PolynomialClosure
from screwkin.model.kernel.compiled import available as numba_available
from screwkin.model.kernel.contract import ClosureKernel, NotProvided
from screwkin.model.kernel.stacks import BatchClosure, Unbatchable

ROBOTS = Path(__file__).resolve().parents[3] / "robots"
MECHANISMS = ["fourbar_crank_rocker", "rssr", "slider_crank_offset", "bennett", "planar_3rpr", "gough_stewart_6ups"]
REAL = ["pinocchio", "stacks", "compiled"]


def load(name):
    return screwkin.load(ROBOTS / f"{name}.urdf")


def backend(mech, kind) -> ClosureKernel | None:
    """The backend ``kind`` of mech's closure rows, or None where that backend declines the mechanism --
    the stacks by raising Unbatchable, the compiled kernels (fixed and spherical cut joints only) by
    accelerate() answering False; a test then checks nothing more of it (no skip: the decline is an answer)."""
    if kind == "pinocchio":
        return mech.closure.pinocchio
    if kind == "stacks":
        try:
            return BatchClosure(mech)
        except Unbatchable as exc:
            assert str(exc)
            return None
    pytest.importorskip("numba")
    assert numba_available()
    fast = screwkin.load(mech.path)  # its own copy: accelerate() changes the closure it is asked of
    if not fast.closure.accelerate():
        assert any(c.type not in ("fixed", "spherical") for c in fast.cuts)
        return None
    return fast.closure.kernel


def random_stack(mech, n=3, seed=0):
    rng = np.random.default_rng(seed)
    return np.array([pin.integrate(mech.model, pin.neutral(mech.model), rng.normal(size=mech.nv))
                     for _ in range(n)])


def finite_differences(kernel, Q, h=1e-6):
    """dr/dv (N, m, nv) by central differences of the kernel's rows along its own steps."""
    N = len(Q)
    out = np.zeros((N, kernel.m, kernel.nv), dtype=np.result_type(Q.dtype, float))
    for j in range(kernel.nv):
        E = np.zeros((N, kernel.nv))
        E[:, j] = h
        plus = kernel.evaluate(kernel.integrate(Q, E), False)[0]
        minus = kernel.evaluate(kernel.integrate(Q, -E), False)[0]
        out[:, :, j] = (plus - minus) / (2 * h)
    return out


@pytest.mark.parametrize("kind", REAL)
@pytest.mark.parametrize("name", MECHANISMS)
def test_real_backends_give_pinocchios_rows(name, kind):
    mech = load(name)
    kernel = backend(mech, kind)
    if kernel is None:
        return
    reference = mech.closure.pinocchio
    assert isinstance(kernel, ClosureKernel) and isinstance(reference, ClosureKernel)
    assert (kernel.nq, kernel.nv, kernel.m) == (mech.model.nq, mech.nv, reference.m)
    Q = random_stack(mech)
    r, K = kernel.evaluate(Q, True)
    assert r.shape == (3, kernel.m) and K.shape == (3, kernel.m, kernel.nv)
    for i, q in enumerate(Q):  # the reference: Pinocchio, one configuration at a time
        r0, K0 = mech.closure.evaluate(q, jacobian=True, solver=True)
        np.testing.assert_allclose(r[i], r0, rtol=0, atol=1e-12)
        np.testing.assert_allclose(K[i], K0, rtol=0, atol=1e-12)
    r_only, none = kernel.evaluate(Q, False)
    assert none is None
    np.testing.assert_allclose(r_only, r, rtol=0, atol=1e-12)
    np.testing.assert_allclose(K, finite_differences(kernel, Q), rtol=0, atol=1e-6)
    V = np.random.default_rng(1).normal(size=(3, mech.nv))
    moved = kernel.integrate(Q, V)
    for i in range(3):
        np.testing.assert_allclose(moved[i], pin.integrate(mech.model, Q[i], V[i]), rtol=0, atol=1e-14)


@pytest.mark.parametrize("kind", REAL)
@pytest.mark.parametrize("name", MECHANISMS)
def test_constraint_jacobian_and_bias_at_a_closed_configuration(name, kind):
    """The minimal rows' Jacobian and their acceleration term K0'(q, v) v: Pinocchio's (ClosureSystem),
    and the bias equal to the second central difference of the rows along a closed motion's tangent."""
    mech = load(name)
    kernel = backend(mech, kind)
    if kernel is None:
        return
    q = mech.generic_configurations()[0].q
    K0 = kernel.constraint_jacobian(q[None])[0]
    np.testing.assert_allclose(K0, mech.closure.jacobian(q), rtol=0, atol=1e-10)
    N = np.linalg.svd(K0)[2][np.linalg.matrix_rank(K0, 1e-9):].T  # null space: rates that keep closure
    v = N @ np.ones(N.shape[1]) if N.size else np.zeros(mech.nv)
    b = kernel.bias(q[None], v[None])[0]
    np.testing.assert_allclose(b, mech.closure.bias(q, v), rtol=0, atol=1e-9)
    h = 1e-4  # K0'(q, v) v = d2/dt2 r(q (+) t v) at t = 0 (r on the minimal rows, zero at q)
    if not mech.closure.position_rows.size or any(c.type in ("fixed", "prismatic") for c in mech.cuts):
        return  # a rotation vector's rows: log3 is second-order only at the identity; checked above against Pinocchio
    rp = mech.closure.residual(pin.integrate(mech.model, q, h * v))
    rm = mech.closure.residual(pin.integrate(mech.model, q, -h * v))
    np.testing.assert_allclose(b, (rp + rm - 2 * mech.closure.residual(q)) / h**2, rtol=0, atol=1e-4)


@pytest.mark.parametrize("kind", REAL)
def test_free_columns_and_the_one_scaling(kind):
    mech = load("slider_crank_offset")
    kernel = backend(mech, kind)
    if kernel is None:
        return
    np.testing.assert_array_equal(kernel.free_columns([0]), np.arange(1, mech.nv))
    K = kernel.evaluate(random_stack(mech, 2), True)[1]
    L = 0.37
    S = kernel.dimensionless(K, L)
    expected = K.copy()
    for i in range(kernel.m):
        for j in range(kernel.nv):
            expected[:, i, j] *= (1 / L if kernel.length_rows[i] else 1.0) * (L if mech.translational[j] else 1.0)
    np.testing.assert_allclose(S, expected, rtol=1e-15, atol=0)
    assert mech.translational.any() and kernel.length_rows.any()


@pytest.mark.parametrize("name", ["fourbar_crank_rocker", "rssr", "slider_crank_offset", "bennett"])
def test_polynomial_backend_vanishes_where_pinocchio_closes(name):
    mech = load(name)
    solver = PositionSolver(mech)
    pc = PolynomialClosure(mech.model, mech.cuts, solver.frozen, mech.length, points=solver._points,
                           compiled=False, eliminate=False)
    assert isinstance(pc, ClosureKernel)
    q = mech.generic_configurations()[0].q
    pc.set_inputs(q)
    x = pc.from_q(q)[None]
    r, J = pc.evaluate(x, True)
    assert r.shape == (1, pc.m) and J.shape == (1, pc.m, pc.nv)
    assert np.abs(r).max() < 1e-12
    assert np.abs(mech.closure.evaluate(q, jacobian=False, solver=True)[0]).max() < 1e-9
    X = pc.random_points(np.random.default_rng(2), 3)  # complex points of the variety
    np.testing.assert_allclose(pc.evaluate(X, True)[1], finite_differences(pc, X), rtol=0, atol=1e-5)
    for k, q_far in enumerate(random_stack(mech, 3, seed=5)):  # where Pinocchio's rows do not vanish, neither do these
        pc.set_inputs(q_far)
        far = np.linalg.norm(pc.evaluate(pc.from_q(q_far)[None], False)[0])
        pin_far = np.linalg.norm(mech.closure.evaluate(q_far, jacobian=False, solver=True)[0])
        assert (far > 1e-6) == (pin_far > 1e-6), (k, far, pin_far)
    with pytest.raises(NotProvided):
        pc.bias(X, np.zeros((3, pc.nv)))
    with pytest.raises(NotImplementedError):
        pc.constraint_jacobian(X)

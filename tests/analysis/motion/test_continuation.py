"""The one continuation (issue 37 item 1): analysis/motion/continuation.py's shared pieces and its engines,
against references outside the code.

The crank-rocker four-bar of robots/fourbar_crank_rocker.urdf: ground O1 = (0, 0), O2 = (d, 0), d = 0.10 m;
crank O1A, a = 0.04 m, drawn at 60 deg; coupler AB, b = 0.12 m; rocker O2B, c = 0.08 m; all axes along z.

Freudenstein: with theta2 the crank's world angle and theta4 the rocker's, B = O2 + c (cos theta4, sin theta4)
and A = a (cos theta2, sin theta2); |B - A|^2 = b^2 expands to
    P cos theta4 + Q sin theta4 = R,  P = 2 d c - 2 a c cos theta2,  Q = -2 a c sin theta2,
    R = 2 d a cos theta2 - (a^2 + c^2 + d^2 - b^2),
so theta4 = atan2(Q, P) +- acos(R / sqrt(P^2 + Q^2)), the sign the drawing's (its assembly mode).

The rocker's extreme angles (a rocker-driven crank-rocker's limit positions): crank and coupler collinear,
|O1 B| = b + a (extended) or b - a (folded); |O1 B|^2 = d^2 + c^2 + 2 d c cos theta4 (law of cosines) gives
cos theta4 = (L^2 - d^2 - c^2) / (2 d c).
"""

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose

import screwkin
from screwkin.analysis.motion.batch_sweep import BatchedCurve, batch_closure
from screwkin.analysis.motion.continuation import (Curve, Neighbour, jumped, locate, orient, passes_limit,
                                                   projections)
from screwkin.analysis.position.position import PositionSolver
from screwkin.analysis.motion.sweep import sweep

ROOT = Path(__file__).resolve().parents[3]
A_, B_, C_, D_ = 0.04, 0.12, 0.08, 0.10
THETA2_0 = np.pi / 3  # the crank as drawn
THETA4_0 = np.arctan2(0.07247123666099901, 0.03388096599604964)  # the rocker as drawn (B - O2)
THETA3_0 = np.arctan2(0.03783022050962147, 0.1138809659960496)  # the coupler as drawn (B - A)


@pytest.fixture(scope="module")
def mech():
    return screwkin.load(ROOT / "robots" / "fourbar_crank_rocker.urdf")


def freudenstein(theta2):
    """(theta3, theta4) world angles of coupler and rocker on the drawing's assembly mode."""
    theta2 = np.asarray(theta2, float)
    P = 2 * D_ * C_ - 2 * A_ * C_ * np.cos(theta2)
    Q = -2 * A_ * C_ * np.sin(theta2)
    R = 2 * D_ * A_ * np.cos(theta2) - (A_**2 + C_**2 + D_**2 - B_**2)
    base, spread = np.arctan2(Q, P), np.arccos(R / np.hypot(P, Q))
    # the drawing's sign: the one that gives THETA4_0 at THETA2_0
    sign = min((1, -1), key=lambda s: abs(np.angle(np.exp(1j * (np.arctan2(
        -2 * A_ * C_ * np.sin(THETA2_0), 2 * D_ * C_ - 2 * A_ * C_ * np.cos(THETA2_0)) + s * np.arccos(
        (2 * D_ * A_ * np.cos(THETA2_0) - (A_**2 + C_**2 + D_**2 - B_**2)) / np.hypot(
            2 * D_ * C_ - 2 * A_ * C_ * np.cos(THETA2_0), 2 * A_ * C_ * np.sin(THETA2_0))) - THETA4_0)))))
    theta4 = base + sign * spread
    Bx, By = D_ + C_ * np.cos(theta4), C_ * np.sin(theta4)
    theta3 = np.arctan2(By - A_ * np.sin(theta2), Bx - A_ * np.cos(theta2))
    return theta3, theta4


def joint_angles(theta2):
    """(crank, coupler, rocker) joint values from the closed form: the joints are zero as drawn, the
    coupler's angle relative to the crank."""
    theta3, theta4 = freudenstein(theta2)
    crank = theta2 - THETA2_0
    wrap = lambda a: np.angle(np.exp(1j * a))  # noqa: E731
    return crank, wrap(theta3 - THETA3_0 - crank), wrap(theta4 - THETA4_0)


@pytest.mark.parametrize("engine", [dict(closed_form=False, batch=False), dict(closed_form=False), dict()])
def test_every_engine_follows_freudenstein(mech, engine):
    """The tracker, the batched corrector and the closed form reach the rocker and coupler angles of
    Freudenstein's equation at every grid value of a full crank turn."""
    solver = PositionSolver(mech, ["crank_joint"])
    res = sweep(solver, "crank_joint", 0.0, 2 * np.pi, 180, **engine)
    assert res.completed and len(res.values) == 181
    _, coupler, rocker = joint_angles(THETA2_0 + res.values)
    j = res.names.index
    wrap = lambda a: np.angle(np.exp(1j * a))  # noqa: E731
    # the batched Newton stops once the loop residual is under Tolerances.closure (1e-10 m): over the
    # 4 cm crank at a poor transmission angle that is a few 1e-9 rad; the others polish further
    atol = 1e-8 if res.method == "batched" else 1e-9
    assert_allclose(wrap(res.joints[:, j("rocker_joint")] - rocker), 0, rtol=0, atol=atol)
    assert_allclose(wrap(res.joints[:, j("coupler_joint")] - coupler), 0, rtol=0, atol=atol)
    assert res.method == ("tracker" if engine.get("batch") is False else "batched" if engine else "closed form")


def test_the_tangent_is_the_closed_forms_derivative_and_a_finite_difference(mech):
    """Curve.tangent at a configuration is the unit vector along (1, d coupler, d rocker) / d crank of the
    closed form (central differences of Freudenstein's angles), and along a finite difference of the
    curve itself (two corrected steps either side, pin.difference on the configuration manifold)."""
    solver = PositionSolver(mech, ["crank_joint"])
    curve = Curve(solver, "crank_joint")
    x, h = 0.7, 1e-6
    res = sweep(solver, "crank_joint", 0.0, x, 70, closed_form=False, batch=False)
    q = res.q[-1]
    t = curve.tangent(q)
    iv = [mech.coordinate(n).idx_v for n in ("crank_joint", "coupler_joint", "rocker_joint")]
    lo, hi = np.array(joint_angles(THETA2_0 + x - h)), np.array(joint_angles(THETA2_0 + x + h))
    d = np.angle(np.exp(1j * (hi - lo))) / (2 * h)
    ref = np.zeros(mech.nv)
    ref[iv] = d / np.linalg.norm(d)
    assert_allclose(t, ref if t @ ref > 0 else -ref, rtol=0, atol=1e-8)
    # the curve's own finite difference: the configurations at x -+ h, each closed with the input held
    qm, qp = curve.at_input(q, x, x - h, t), curve.at_input(q, x, x + h, t)
    fd = pin.difference(mech.model, qm, qp)
    assert_allclose(t, fd / np.linalg.norm(fd) * np.sign(t[iv[0]]), rtol=0, atol=1e-8)


def limits_by_the_law_of_cosines():
    """The rocker's joint values at its extremes: crank and coupler collinear (module docstring)."""
    out = []
    for L in (B_ + A_, B_ - A_):
        theta4 = np.arccos((L**2 - D_**2 - C_**2) / (2 * D_ * C_))  # the drawing's side: above the ground
        out.append(theta4 - THETA4_0)
    return out


@pytest.mark.parametrize("batch", [False, True])
def test_a_limit_is_located_where_the_inputs_share_of_the_tangent_vanishes(mech, batch):
    """Driving the rocker down and up from the drawing: each sweep stops at a limit position located to
    1e-9 of the law of cosines' extreme, where the input's direction projected on the curve (P e) is
    nil and crank and coupler are collinear."""
    solver = PositionSolver(mech, ["rocker_joint"])
    curve = Curve(solver, "rocker_joint")
    extended, folded = limits_by_the_law_of_cosines()
    assert extended < 0 < folded
    for stop, expected, L in ((-1.0, extended, B_ + A_), (1.5, folded, B_ - A_)):
        res = sweep(solver, "rocker_joint", 0.0, stop, 100, closed_form=False, batch=batch)
        assert len(res.limits) == 1 and res.limits[0].limit
        lim = res.limits[0]
        assert abs(lim.input - expected) < 1e-9 and res.stopped_at == lim.input
        K = mech.closure.jacobian(lim.q)[None]
        share = curve.input_directions(K)[0]
        assert np.linalg.norm(share) < 1e-9  # (0.30 at the drawing)
        frame = mech.model.getFrameId("coupler")
        data = mech.model.createData()
        pin.framesForwardKinematics(mech.model, data, lim.q)
        B = data.oMf[frame].act(np.array([0.1138809659960496, 0.03783022050962147, 0.0]))
        assert abs(np.linalg.norm(B[:2]) - L) < 1e-9


def test_batched_tangents_are_the_curves_tangents():
    """BatchedCurve's stacked tangents, oriented in a chain, equal Curve.tangent one configuration at a
    time, each oriented like the one before (Bennett's spatial linkage, 40 configurations)."""
    mech = screwkin.load(ROOT / "robots" / "bennett.urdf")
    name = mech.actuated[0] if mech.actuated else mech.coordinates[0].joint
    solver = PositionSolver(mech, [name])
    res = sweep(solver, name, 0.0, 4.0, 40, batch=False)
    curve = Curve(solver, name)
    batched = BatchedCurve(solver, name, batch_closure(mech))
    previous = curve.tangent(res.q[0])
    T = batched.tangents(res.q, previous)
    for q, tb in zip(res.q, T):
        previous = curve.tangent(q, previous)
        assert_allclose(tb, previous, rtol=0, atol=1e-10)


def test_the_shared_rules_by_hand():
    tol = screwkin.Tolerances()
    # jump test: more than half the step, or the floor for a nil step; NaN jumped
    assert not jumped(0.05, 0.1, tol) and jumped(0.0501, 0.1, tol) and jumped(0.06, -0.1, tol)
    assert not jumped(0.5 * tol.jump_floor, 0.0, tol) and jumped(2 * tol.jump_floor, 0.0, tol)
    assert list(jumped(np.array([np.nan, 0.0]), np.array([1.0, 1.0]), tol)) == [True, False]
    # branch rule: each row oriented like the one before, the first like the previous tangent
    t = np.array([[1.0, 0.0], [-1.0, 0.1], [1.0, 0.2], [0.0, 1.0]])
    o = orient(t, np.array([-1.0, 0.0]))
    assert_allclose(o, [[-1, 0], [-1, 0.1], [-1, -0.2], [0, -1]], rtol=0, atol=0)
    assert_allclose(orient(np.array([1.0, 0.0]), np.array([-1.0, 0.2])), [-1.0, 0.0], rtol=0, atol=0)
    assert passes_limit(np.array([0.3, 1.0]), np.array([-0.1, 1.0]), 0)
    assert not passes_limit(np.array([-0.3, 1.0]), np.array([-0.1, 1.0]), 0)
    # the projection onto ker K: K = [1 1] (scale 1): P e0 = (1/2, -1/2); a held column has no part
    P = projections(np.array([[[1.0, 1.0, 5.0]]]), np.array([[1.0, 0.0, 0.0]]), np.ones(3), np.array([0, 1]), tol)
    assert_allclose(P, [[0.5, -0.5, 0.0]], rtol=0, atol=1e-15)
    # Brent's root of a sign change: cos on [0, 3] at pi / 2
    assert abs(locate(np.cos, 0.0, 3.0) - np.pi / 2) < 1e-14


def test_a_neighbour_step_is_refused_across_a_limit(mech):
    """Neighbour (a map's step) reaches a value on the branch, and refuses one past the rocker's extreme."""
    solver = PositionSolver(mech, ["rocker_joint"])
    step = Neighbour(solver, "rocker_joint")
    q0 = mech.assemble().q
    extended, _ = limits_by_the_law_of_cosines()
    q = step(q0, 0.0, 0.5 * extended)
    assert q is not None
    assert abs(q[mech.coordinate("rocker_joint").idx_q] - 0.5 * extended) < 1e-12
    assert step(q0, 0.0, extended - 0.05) is None


def test_every_engine_has_the_interface():
    """The engines -- per step, batched, closed form -- each answer the five questions of the interface."""
    from screwkin.analysis.motion.continuation import Engine
    from screwkin.analysis.motion.dyads import ClosedFormCurve

    questions = [n for n in vars(Engine) if not n.startswith("_")]
    assert sorted(questions) == ["accept", "choose_branch", "correct", "locate_limit", "predict"]
    for engine in (Curve, BatchedCurve, ClosedFormCurve):
        assert all(callable(getattr(engine, n, None)) for n in questions), engine
    # the certified mode search's homotopy paths: predict, correct, accept (no branch nor limit in C^n)
    from screwkin.model.homotopy.tracking import Paths

    assert all(callable(getattr(Paths, n, None)) for n in ("predict", "correct", "accept"))

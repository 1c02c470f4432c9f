"""The public example-parallel-robots files (written by others) load and get a mobility.

Expected values are derived by hand from each file's joint list (see the reason
next to each): links N and joints J after merging welded links and counting
three revolutes through massless links as one spherical joint, Kutzbach
F = 6(N-1-J) + sum f (Gruebler with 3 for the planar ones), and the idle
motions visible in the design (an S-S rod spinning about its own axis, an
S-P-S leg spinning about its line, a link held by two coaxial revolutes).
"""

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import CORPUS
from screwkin.model.kernel.closure import ClosureSystem
from screwkin.tolerances import Tolerances

# name: (N, J, count, motion space, M, idle, actuated count, classification start, reason)
EXPECTED = {
    "5bar_linkage": (6, 6, 3, "planar", 3, 1, 2, "constrained",
                     "planar five-bar; its loop is closed by a 6d weld of two 'sphere' links each on a revolute "
                     "coaxial with the other, so the welded pair spins idle: Gruebler 3(6-1-6)+6 = 3, minus 1 idle = 2 motors"),
    "5bar_linkage_iso3d": (6, 6, 2, "spatial", 2, 0, 2, "constrained",
                           "five-bar closed by a 3d (spherical) contact: 5 R + 1 S, 6(6-1-6)+8 = 2, isostatic"),
    "cassie_like": (10, 11, 7, "spatial", 7, 2, 5, "constrained",
                    "leg with two S-S rods (plantar rod, Achilles rod), each spherical = 3 revolutes through massless "
                    "links; 6(10-1-11)+19 = 7, two rods spin idle, 5 motors"),
    "digit_like": (13, 15, 9, "spatial", 9, 3, 6, "constrained",
                   "three S-S rods: 6(13-1-15)+27 = 9, three spin idle, 6 motors"),
    "robot_delta": (12, 14, 5, "planar", 5, 3, 2, "constrained",
                    "planar 2-DOF delta: three loops each closed by a weld of two links on coaxial revolutes "
                    "(3 idle spins); Gruebler 3(12-1-14)+14 = 5, 5 - 3 = 2 motors"),
    "talos_like": (9, 9, 7, "spatial", 7, 1, 6, "constrained",
                   "6R leg whose ankle is driven by one S-S rod from motor_shin: 6(9-1-9)+13 = 7, the rod spins idle"),
    "wl16_like": (14, 18, 12, "spatial", 12, 6, 6, "constrained",
                  "six S-P-S linear-actuator legs (prismatic motors): 6(14-1-18)+42 = 12, each leg spins about its "
                  "own line (6 idle), 6 motors"),
    "disney_like": (15, 17, 9, "spatial", 9, 2, 6, "unconstrained",
                    "five S joints and a U (two revolutes through the massive link 'universal'): 6(15-1-17)+27 = 9; "
                    "two S-S rods spin idle; 7 effective DOF for 6 motors: one passive DOF remains at the ankle "
                    "(checked by a finite motion below)"),
}


def load(name):
    return screwkin.load(CORPUS / name / "robot.urdf", warn=lambda m: None)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_corpus_mobility(name):
    N, J, count, space, M, idle, m, kind, _reason = EXPECTED[name]
    r = load(name).mobility()
    t = r.topology
    assert (t.n_links, t.n_joints) == (N, J)
    assert t.motion_space == space
    assert t.count_in_motion_space == count
    assert r.mobility == M
    assert r.idle_dofs == idle
    assert r.effective_mobility == M - idle
    assert len(r.actuated) == m
    assert r.actuation_source == "yaml name_mot"
    assert r.classification.startswith(kind)
    # overconstraint = rows - rank = M - Kutzbach count (an identity of the counts)
    assert r.overconstraint == r.constraint_rows - r.rank == r.mobility - t.kutzbach
    assert r.residual < 1e-10


def test_all_corpus_folders_are_covered():
    folders = {p.name for p in CORPUS.iterdir() if (p / "robot.urdf").exists()}
    assert folders == set(EXPECTED) | {"kangaroo_like"}


def test_disney_extra_dof_is_a_finite_motion():
    """Second method for disney_like's passive DOF: hold all six motor joints
    and move the mechanism a finite distance along the free direction; the
    loops close again at a different configuration."""
    mech = load("disney_like")
    r = mech.mobility()
    q = r.q
    act = mech.velocity_indices(mech.actuated)
    K = mech.closure.jacobian(q)
    _, s, vt = np.linalg.svd(np.vstack([K, np.eye(mech.nv)[act]]))
    free = vt[-1]
    moved = mech.closure.solve(pin.integrate(mech.model, q, 0.05 * free), frozen=act)
    dq = pin.difference(mech.model, q, moved.q)
    np.testing.assert_allclose(dq[act], 0.0, atol=1e-12)
    assert np.linalg.norm(dq) > 0.01
    assert moved.residual < 1e-10


def test_kangaroo_loads_but_cannot_be_assembled():
    """kangaroo_like's eleven loops are '6d' welds; five of them cannot close
    even alone (the smallest residual is the same from many random starts),
    so screwkin refuses to report a mobility rather than analyse an open
    configuration."""
    mech = load("kangaroo_like")
    topo = mech.topology(mech.neutral())  # topology needs no assembly
    assert topo.loops == 11
    with pytest.raises(screwkin.AssemblyError) as err:
        mech.mobility()
    assert err.value.residual > 1e-3
    assert "residual" in str(err.value)
    # independent check on one loop alone, from random starts
    cut = next(c for c in mech.cuts if c.name.startswith("closedloop2_A"))
    alone = ClosureSystem(mech.model, [cut])
    rng = np.random.default_rng(1)
    best = np.inf
    for _ in range(8):
        q0 = pin.integrate(mech.model, mech.neutral(), rng.normal(size=mech.nv))
        with pytest.raises(screwkin.AssemblyError) as e:
            alone.solve(q0)
        best = min(best, e.value.residual)
    assert best > 4e-3


def test_corpus_output_motion_of_the_cassie_foot():
    """Cassie-like leg: 5 motors drive the foot in 5 dimensions (the foot pitch
    is driven through the plantar rod)."""
    r = load("cassie_like").mobility(output="foot_2")
    assert r.output.dimension == 5
    assert r.effective_dofs == 5


def test_missing_meshes_warn_but_load():
    seen = []
    screwkin.load(CORPUS / "talos_like" / "robot.urdf", warn=seen.append)
    assert any("mesh" in w for w in seen)


def joint_centres(mech, q):
    """World positions of every joint frame origin: idle spins move none of them."""
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    ids = [f for f, fr in enumerate(mech.model.frames) if fr.type == pin.FrameType.JOINT]
    return np.concatenate([data.oMf[f].translation for f in ids]), ids


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_corpus_solves_for_motor_inputs(name):
    """Read the motor values of another assembled configuration (a random step
    along the null space of K, closed again) and solve for them from the file's
    assembly: the loops close, the motors hold their values, and the joint
    rates from K q' = 0 move every joint centre as a central finite difference
    of two nearby solutions does (joint centres do not see idle spins).
    A motor step is not used: several of these files assemble next to an
    actuator singularity, where some motor steps cannot be followed at all."""
    from screwkin.model.linalg import null_space
    from screwkin.analysis.position.position import PositionSolver

    # a tight closure tolerance so that a small finite-difference step is not drowned in it:
    # wl16_like assembles next to a singularity, where the motion curves sharply
    mech = screwkin.load(CORPUS / name / "robot.urdf", warn=lambda m: None, tolerances=Tolerances(closure=1e-13))
    solver = PositionSolver(mech)
    q0 = mech.assemble().q
    V = null_space(mech.closure.jacobian(q0), mech.tolerances, mech.nv)
    step = V @ np.random.default_rng(5).normal(size=V.shape[1])
    q1 = mech.closure.solve(pin.integrate(mech.model, q0, 0.05 * step / np.linalg.norm(step))).q
    target = {n: v for n, v in solver.joint_values(q1).items() if n in mech.actuated}
    # motor rates of a feasible motion (not all motors at once: that may need huge passive rates here)
    direction = dict(zip(mech.actuated, (null_space(mech.closure.jacobian(q1), mech.tolerances, mech.nv)
                                          @ np.random.default_rng(6).normal(size=V.shape[1]))[solver.frozen]))
    res = solver.solve(target, near=solver.joint_values(q0), rates=direction, starts=0)
    s = res.solutions[0]
    assert s.residual < 1e-10
    for n, v in target.items():
        assert abs(np.mod(s.joints[n] - v + np.pi, 2 * np.pi) - np.pi) < 1e-12
    if res.free_dofs:
        return  # the inputs leave a DOF free (disney_like): the rates are not unique
    if name == "wl16_like":
        # assembled next to an actuator singularity: the passive joints are barely determined
        # (relative smallest singular value below 1e-4), so finite differences wander; the root is
        # ill-conditioned but simple (Newton comes back quadratically: modes.simple_root), so it is
        # not flagged singular (issue 35: singular only where the Jacobian loses rank)
        assert s.sigma_min < 1e-4 and s.simple and not s.singular
        return
    # h: the closure tolerance and the idle spins (left by Newton at about 1e-11 rad, and
    # moving the tip joints of robot_delta's rods) over 2h, against h^2 truncation
    h = 1e-4
    plus = solver.solve({n: v + h * direction[n] for n, v in target.items()}, near=s.joints, starts=0).solutions[0]
    minus = solver.solve({n: v - h * direction[n] for n, v in target.items()}, near=s.joints, starts=0).solutions[0]
    fd = (joint_centres(mech, plus.q)[0] - joint_centres(mech, minus.q)[0]) / (2 * h)
    _, ids = joint_centres(mech, s.q)
    data = mech.model.createData()
    pin.computeJointJacobians(mech.model, data, s.q)
    pin.updateFramePlacements(mech.model, data)
    vel = np.concatenate([pin.getFrameJacobian(mech.model, data, f, pin.LOCAL_WORLD_ALIGNED)[:3] @ s.qdot
                          for f in ids])
    np.testing.assert_allclose(vel, fd, rtol=1e-5, atol=1e-6)

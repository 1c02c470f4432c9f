"""Independent oracles for what screwkin computes: values taken from outside the code under test.

- loop rows: Pinocchio's own constraint models (``RigidConstraintModel`` with CONTACT_6D for a
  weld / fixed cut joint, CONTACT_3D for a ball / spherical one) and finite differences on the
  manifold (``pin.integrate``) of a residual written here from the frame placements alone;
- the product of exponentials: modern_robotics' ``FKinSpace`` and ``JacobianSpace``;
- statics: Bennett's input torque by virtual work (the mechanism moved along its one DOF);
- legs' wrenches: lines and twist spaces written in closed form from the file's joint centres.
"""

import json

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import CORPUS, ROBOTS

LOCAL = pin.ReferenceFrame.LOCAL
LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED

# files whose cut joints are all fixed (6 rows each) or all spherical (3 rows each)
WELDED = [CORPUS / n / "robot.urdf" for n in ("cassie_like", "robot_delta", "5bar_linkage", "talos_like", "digit_like")]
BALLS = [CORPUS / "5bar_linkage_iso3d" / "robot.urdf", ROBOTS / "gough_stewart_6ups.urdf",
         ROBOTS / "delta_parallelogram.urdf", ROBOTS / "rssr.urdf"]


def _name(path):
    return path.parent.name if path.name == "robot.urdf" else path.stem


def _configurations(mech, n_random=3, seed=5):
    """Generic closed configurations (screwkin's own search: only where the rows are compared,
    never what they are compared with), then ones off the closure manifold: a random step of
    up to 0.5 rad (or m) per joint from a closed one, so that no cut frame turns near pi
    relative to the other (where log3 and its finite differences lose their digits)."""
    _, closed = mech.generic_configurations()
    rng = np.random.default_rng(seed)
    free = [pin.integrate(mech.model, closed[k % len(closed)], rng.uniform(-0.5, 0.5, mech.nv))
            for k in range(n_random)]
    return [(q, True) for q in closed[:3]] + [(q, False) for q in free]


def _pin_rows(model, data, contact_type, j1, M1, j2, M2, reference):
    """Pinocchio's constraint Jacobian of a constraint between placement M1 on joint j1 and M2
    on joint j2, at the configuration data was computed at (calc first: see
    /work/shared/pinocchio-notes.md), in the axes of the constraint's frame 1: LOCAL rows as
    they come, LOCAL_WORLD_ALIGNED rows (world axes) turned by that frame's rotation."""
    cm = pin.RigidConstraintModel(contact_type, model, j1, M1, j2, M2, reference)
    cd = cm.createData()
    cm.calc(model, data, cd)
    K = pin.getConstraintJacobian(model, data, cm, cd)
    if reference == LOCAL:
        return K
    R1 = (data.oMi[j1] * M1).rotation
    return np.kron(np.eye(len(K) // 3), R1.T) @ K


def _oracle_K(mech, q, reference=LOCAL, mapped=True):
    """The stacked constraint Jacobian that Pinocchio's constraint models give, mapped onto the
    rows screwkin documents (positions R1^T (o2 - o1), then log3(R1^T R2) for a weld) by a map T
    written here in closed form.

    Pinocchio's LOCAL 6-D rows are minus the motion of frame 2 relative to frame 1, expressed
    in frame 1 at its origin, -(1X2 V2 - V1) (the sign opposite to a log6(1M2) residual).
    With (R, p) = 1M2 the rows of d/dt (R1^T (o2 - o1), log3 R) are T (-K_pin),
    T = [[I, -[p]x], [0, Jlog3(R) R^T]].
    A 3-D contact compares the velocities of two points; screwkin's rows differentiate
    R1^T (o2 - o1), the motion of o2 relative to the body of frame 1, so the oracle's point on
    body 1 is the one at o2 now (the same frame when the loop is closed).

    mapped=False: Pinocchio's rows as they come, for the cut frames as written (no T, no
    moved point), whose row space is the loop's constraint wrenches at a closed configuration."""
    model = mech.model
    data = model.createData()
    pin.computeJointJacobians(model, data, q)
    pin.framesForwardKinematics(model, data, q)
    blocks = []
    for cut in mech.cuts:
        f1, f2 = model.frames[cut.frame1], model.frames[cut.frame2]
        oM1, oM2 = data.oMf[cut.frame1], data.oMf[cut.frame2]
        if cut.type == "fixed":
            K = -_pin_rows(model, data, pin.ContactType.CONTACT_6D, f1.parentJoint, f1.placement,
                           f2.parentJoint, f2.placement, reference)
            M = oM1.inverse() * oM2
            T = np.eye(6)
            T[:3, 3:] = -pin.skew(M.translation)
            T[3:, 3:] = pin.Jlog3(M.rotation) @ M.rotation.T
            blocks.append(T @ K if mapped else K)
        elif cut.type == "spherical" and not mapped:
            blocks.append(-_pin_rows(model, data, pin.ContactType.CONTACT_3D, f1.parentJoint, f1.placement,
                                     f2.parentJoint, f2.placement, reference))
        elif cut.type == "spherical":
            at_o2 = data.oMi[f1.parentJoint].inverse() * pin.SE3(oM1.rotation, oM2.translation)
            blocks.append(-_pin_rows(model, data, pin.ContactType.CONTACT_3D, f1.parentJoint, at_o2,
                                     f2.parentJoint, f2.placement, reference))
        else:
            raise AssertionError(f"no oracle here for a {cut.type} cut joint")
    return np.vstack(blocks)


def _residual_here(mech, q):
    """The weld and ball rows written from the frame placements alone (not screwkin's closure
    code): R1^T (o2 - o1), and log3(R1^T R2) for a weld."""
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    rows = []
    for cut in mech.cuts:
        M = data.oMf[cut.frame1].inverse() * data.oMf[cut.frame2]
        rows.append(M.translation)
        if cut.type == "fixed":
            rows.append(pin.log3(M.rotation))
    return np.concatenate(rows)


def _fd(mech, q, h=1e-6):
    cols = []
    for i in range(mech.nv):
        e = np.zeros(mech.nv)
        e[i] = h
        cols.append((_residual_here(mech, pin.integrate(mech.model, q, e))
                     - _residual_here(mech, pin.integrate(mech.model, q, -e))) / (2 * h))
    return np.stack(cols, axis=1)


def _projector(K, rtol=1e-9):
    u, s, vt = np.linalg.svd(K)
    rank = int((s > rtol * s[0]).sum())
    return vt[:rank].T @ vt[:rank], rank


@pytest.mark.parametrize("reference", [LOCAL, LWA], ids=["LOCAL", "LOCAL_WORLD_ALIGNED"])
@pytest.mark.parametrize("path", WELDED + BALLS, ids=_name)
def test_loop_rows_equal_pinocchios_constraint_models(path, reference):
    mech = screwkin.load(path, warn=lambda m: None)
    assert mech.cuts and not mech.closure.extra
    assert {c.type for c in mech.cuts} == ({"fixed"} if path in WELDED else {"spherical"})
    assert mech.closure.nrows == sum(6 if c.type == "fixed" else 3 for c in mech.cuts)
    for q, closed in _configurations(mech):
        K = mech.closure.jacobian(q)
        oracle = _oracle_K(mech, q, reference)
        assert K.shape == oracle.shape
        scale = max(1.0, np.abs(oracle).max())
        np.testing.assert_allclose(K, oracle, rtol=0, atol=1e-10 * scale)
        # the same rows as finite differences on the manifold of the residual written here
        np.testing.assert_allclose(oracle, _fd(mech, q), rtol=0, atol=2e-7 * scale)
        if not closed:
            assert np.linalg.norm(_residual_here(mech, q)) > 1e-2  # off the manifold: T is not I
        else:
            assert np.linalg.norm(_residual_here(mech, q)) < 1e-9
            # closed: Pinocchio's rows as they come, with no map, span the same row space
            P, rank = _projector(K)
            P_pin, rank_pin = _projector(_oracle_K(mech, q, reference, mapped=False))
            assert rank == rank_pin
            np.testing.assert_allclose(P, P_pin, rtol=0, atol=1e-8)


# ---------------------------------------------------------------------------------------------
# Product of exponentials against modern_robotics (Lynch and Park's own code)

def _serial_chains(path, output):
    from screwkin.analysis.screws import structure

    mech = screwkin.load(path, warn=lambda m: None)
    rng = np.random.default_rng(2)
    for _ in range(4):
        q = pin.integrate(mech.model, pin.neutral(mech.model), rng.uniform(-2, 2, mech.nv))
        yield mech, q, structure(mech, q, output)


def _wv(twists):
    """(v, w) rows (Pinocchio, screwkin) to (w, v) rows (modern_robotics)."""
    return np.vstack([twists[3:], twists[:3]])


@pytest.mark.parametrize("path, output", [(ROBOTS / "arm_6r.urdf", "flange"), (ROBOTS / "planar_3rpr.urdf", None),
                                          (ROBOTS / "bennett.urdf", None)], ids=["arm_6r", "planar_3rpr", "bennett"])
def test_product_of_exponentials_equals_modern_robotics(path, output):
    """screwkin's space screws S_i and home placement M of each chain, given to
    ``mr.FKinSpace(M, Slist, theta)``, give Pinocchio's forward kinematics of the frame, and
    ``mr.JacobianSpace(Slist, theta)`` gives screwkin's space Jacobian, at random configurations."""
    mr = pytest.importorskip("modern_robotics", reason="modern_robotics is not installed (the test extra has it)")
    from screwkin.analysis.screws import poe

    seen = 0
    for mech, q, chains in _serial_chains(path, output):
        data = mech.model.createData()
        pin.framesForwardKinematics(mech.model, data, q)
        for entry in chains:
            ch, theta = entry["chain"], entry["theta"]
            assert len(ch.joints) == len(theta)
            if not ch.joints:  # a cut frame on the ground: no screws, M itself
                np.testing.assert_allclose(ch.g0, data.oMf[ch.frame].homogeneous, rtol=0, atol=1e-12)
                continue
            S = _wv(ch.xi0)
            T_mr = mr.FKinSpace(ch.g0, S, theta)
            np.testing.assert_allclose(T_mr, data.oMf[ch.frame].homogeneous, rtol=0, atol=1e-9)
            np.testing.assert_allclose(poe(ch, theta), T_mr, rtol=0, atol=1e-9)
            np.testing.assert_allclose(_wv(entry["space_jacobian"]), mr.JacobianSpace(S, theta), rtol=0, atol=1e-9)
            np.testing.assert_allclose(entry["g"], T_mr, rtol=0, atol=1e-9)
            seen += 1
    assert seen >= 4  # chains of 2 to 6 joints checked


# ---------------------------------------------------------------------------------------------
# Bennett's input torque by virtual work: the mechanism moved along its one DOF

BENNETT_LOAD = np.array([1.0, 2.0, 3.0, 0.1, 0.2, 0.3])  # (force [N], moment [N m]) on link3, world axes


def _nearest(mech, solutions, q):
    return min((s.q for s in solutions), key=lambda x: np.linalg.norm(pin.difference(mech.model, q, x)))


def _virtual_work_torque(mech, theta, output="link3", wrench=BENNETT_LOAD, h=1e-5):
    """tau at joint1 = theta holding ``wrench`` on ``output``: the mechanism closed at theta and
    at theta +- h (the same assembly mode: the solutions nearest), the output frame's
    displacement twist by central differences of log6 from the middle placement, turned to world
    axes at the frame's origin (the load's convention), and power balance tau h + w . twist = 0."""
    from screwkin.analysis.position.position import PositionSolver

    solver = PositionSolver(mech, ["joint1"])
    q0 = solver.solve({"joint1": theta}).solutions[0].q
    qp = _nearest(mech, solver.solve({"joint1": theta + h}).solutions, q0)
    qm = _nearest(mech, solver.solve({"joint1": theta - h}).solutions, q0)
    for x in (q0, qp, qm):
        assert np.linalg.norm(mech.closure.residual(x)) < 1e-10
    # the step moved the mechanism along its one DOF by about h, not onto another mode
    assert np.linalg.norm(pin.difference(mech.model, qm, qp)) < 100 * h
    data = mech.model.createData()
    fid = mech.link_frame(output)

    def placement(q):
        pin.framesForwardKinematics(mech.model, data, q)
        return data.oMf[fid].copy()

    M0 = placement(q0)
    body = (pin.log6(M0.inverse() * placement(qp)).vector - pin.log6(M0.inverse() * placement(qm)).vector) / (2 * h)
    R = M0.rotation
    twist = np.r_[R @ body[:3], R @ body[3:]]  # (linear velocity of the frame's origin, angular), world axes
    return q0, -twist @ wrench


@pytest.mark.slow  # about 4.4 s on 2 shared cores: out of the fast subset
@pytest.mark.parametrize("theta", [0.3, 1.1, -0.8])
def test_bennett_input_torque_by_virtual_work(theta):
    from screwkin.analysis.forces.statics import statics

    mech = screwkin.load(ROBOTS / "bennett.urdf")
    assert list(mech.actuated) == ["joint1"]
    q0, expected = _virtual_work_torque(mech, theta)
    assert abs(expected) > 1e-3  # a load that the input feels
    r = statics(mech, q0, output="link3", wrench=BENNETT_LOAD)
    assert r.equilibrium and r.indeterminate == 3
    assert r.efforts["joint1"] == pytest.approx(expected, rel=1e-6)


@pytest.mark.slow  # about 2.9 s on 2 shared cores: out of the fast subset
def test_bennett_statics_command_gives_the_virtual_work_torque(capsys):
    from screwkin.cli import main

    mech = screwkin.load(ROBOTS / "bennett.urdf")
    _, expected = _virtual_work_torque(mech, 0.7)
    load = " ".join(map(str, BENNETT_LOAD))
    assert main(["statics", str(ROBOTS / "bennett.urdf"), "--set", "joint1=0.7", "--output", "link3",
                 "--wrench", load, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["units"]["joint1"] == "N m"
    assert out["efforts"]["joint1"] == pytest.approx(expected, rel=1e-6)


# ---------------------------------------------------------------------------------------------
# A Gough-Stewart platform's legs: lines and twist spaces in closed form from the file's centres

def _stewart_centres(path):
    """From the file itself (xml): base U centres B_k and U first axes (the base is the world),
    and the platform's S centres p_k in the platform frame (leg 1's ball is the platform's
    origin; legs 2..6 are loop joints with link2 on the platform)."""
    import xml.etree.ElementTree as ET

    root = ET.parse(path).getroot()
    joints = {j.get("name"): j for j in root.iter("joint")}
    loops = {j.get("name"): j for j in root.iter("loop_joint")}

    def vec(el, attr):
        return np.array([float(x) for x in el.get(attr).split()])

    B = [vec(joints[f"base{k}_a"].find("origin"), "xyz") for k in range(1, 7)]
    A1 = [vec(joints[f"base{k}_a"].find("axis"), "xyz") for k in range(1, 7)]
    p = [np.zeros(3)] + [vec(loops[f"ball{k}"].find("link2"), "xyz") for k in range(2, 7)]
    assert all(loops[f"ball{k}"].find("link2").get("link") == "platform" for k in range(2, 7))
    return B, [a / np.linalg.norm(a) for a in A1], p


def _rotation_twist(u, c, o):
    """Twist (v at o, w) of a rotation about the unit axis u through the point c."""
    return np.r_[np.cross(u, o - c), u]


def test_stewart_transmission_wrenches_are_the_leg_lines_reciprocal_to_the_passive_joints():
    """Each leg k is U-P-S: its line (unit d_k from the U centre B_k to the S centre P_k, moment
    (P_k - o) x d_k about the platform origin o) is the one wrench reciprocal to the five passive
    twists (rotations about the U's axes a1 and a1 x d_k through B_k, and about three axes
    through P_k), and is what the locked actuator transmits.  Everything here is written from
    the file's joint centres and the platform placement (Pinocchio's forward kinematics)."""
    from screwkin.analysis.forces.statics import legs

    path = ROBOTS / "gough_stewart_6ups.urdf"
    mech = screwkin.load(path)
    B, A1, p_local = _stewart_centres(path)
    data = mech.model.createData()
    for q in mech.generic_configurations()[1][:3]:
        pin.framesForwardKinematics(mech.model, data, q)
        oMp = data.oMf[mech.link_frame("platform")]
        o = oMp.translation
        found = {leg.actuated: leg for leg in legs(mech, q, "platform")}
        assert sorted(found) == [(f"leg{k}",) for k in range(1, 7)]
        for k in range(6):
            P = oMp.act(p_local[k])
            d = (P - B[k]) / np.linalg.norm(P - B[k])
            line = np.r_[d, np.cross(P - o, d)]
            a1 = A1[k]
            a2 = np.cross(a1, d) / np.linalg.norm(np.cross(a1, d))  # the U's second axis: across a1 and the leg
            passive = np.array([_rotation_twist(a1, B[k], o), _rotation_twist(a2, B[k], o)]
                               + [_rotation_twist(e, P, o) for e in np.eye(3)]).T
            assert np.linalg.matrix_rank(passive, tol=1e-9) == 5
            np.testing.assert_allclose(line @ passive, 0.0, rtol=0, atol=1e-12)  # the closed form holds
            leg = found[(f"leg{k + 1}",)]
            assert leg.twists == 6 and leg.constraint_wrenches == ()
            (w,) = np.asarray(leg.transmission_wrenches)
            w = w / np.linalg.norm(w[:3]) * np.sign(w[:3] @ d)
            np.testing.assert_allclose(w, line, rtol=0, atol=1e-9)
            np.testing.assert_allclose(w @ passive, 0.0, rtol=0, atol=1e-9)
            assert w @ np.r_[d, np.zeros(3)] == pytest.approx(1.0)  # the actuator's own twist: not reciprocal


# the platform twist spaces in closed form, at the platform origin, (v, w): translations (3T), or
# translations in the xy plane of the planar files and rotations about z (2T1R)
_3T = np.hstack([np.eye(3), np.zeros((3, 3))])
_2T1R = np.array([[1.0, 0, 0, 0, 0, 0], [0, 1.0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 1.0]])


@pytest.mark.parametrize("name, space", [("delta_parallelogram", _3T), ("tsai_3upu", _3T),
                                         ("planar_3rrr", _2T1R), ("planar_3rpr", _2T1R)])
def test_legs_constraint_wrenches_are_reciprocal_to_the_closed_form_platform_twists(name, space):
    """Every leg's constraint wrench w satisfies w . t = 0 for every platform twist t of the
    closed-form space, and together they leave exactly that space (rank 6 - 3); screwkin's
    mobility of the platform is the same space."""
    from screwkin.analysis.forces.statics import legs

    mech = screwkin.load(ROBOTS / f"{name}.urdf")
    for q in mech.generic_configurations()[1][:2]:
        W = np.array([c for leg in legs(mech, q, "platform") for c in leg.constraint_wrenches])
        np.testing.assert_allclose(W @ space.T, 0.0, rtol=0, atol=1e-9)
        assert np.linalg.matrix_rank(W, tol=1e-8) == 3
    twists = np.array(mech.mobility(output="platform").output.twists)  # (3, 6), rows
    assert np.linalg.matrix_rank(np.vstack([twists, space]), tol=1e-8) == 3
